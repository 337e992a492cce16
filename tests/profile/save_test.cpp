// Saving a card into a profile: engineering units, provenance comments, loads back exactly.
#include "profile/save.hpp"

#include <gtest/gtest.h>

#include <chrono>

#include "fake_card.hpp"
#include "profile/validate.hpp"
#include "profile/writer.hpp"
#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;

TEST(ProfileSave, ReadsTheNamedParametersWithProvenance) {
  FakeCard card(db());
  card.values["NVBRAKEONV"] = 19000;
  SaveOptions options;
  options.name = "cell-3 x axis";
  options.when = std::chrono::system_clock::time_point{std::chrono::seconds{1700000000}};
  const Profile p = save(card, db(), {"nvbrakeonv", "NVKQP", "KQP", "NVKQP"}, options);
  ASSERT_EQ(p.settings.size(), 3u);  // duplicates dropped, database spelling
  EXPECT_EQ(p.settings[0].name, "NVBRAKEONV");
  EXPECT_EQ(p.settings[0].raw, 19000);
  const std::string yaml = to_yaml(p, db());
  EXPECT_NE(yaml.find("# Read from fake 8I20 unit 0x00C0FFEE\n# on 2023-11-14T22:13:20Z."), std::string::npos)
      << yaml;
  EXPECT_NE(yaml.find("NVBRAKEONV: 190.00 V"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("KQP: 50"), std::string::npos) << yaml;
  const Profile again = load(yaml);
  EXPECT_EQ(again.name, "cell-3 x axis");
  ASSERT_EQ(again.settings.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(again.settings[i].raw, p.settings[i].raw);
  // Each value goes back to the cell it came from.
  EXPECT_EQ(cells_of(again, again.settings[2], db()), std::vector<std::string>{"KQP"});
}

TEST(ProfileSave, DefaultsToTheEepromSetup) {
  const auto names = default_save_names(db());
  for (const char* expected : {"NVMAXCURRENT", "NVBRAKEONV", "NVBRAKEOFFV", "NVBUSOVERV", "NVBUSUNDERV",
                               "NVKQP", "NVKQI", "NVKDP", "NVKDI", "NVKQIL", "NVKDIL"})
    EXPECT_NE(std::ranges::find(names, expected), names.end()) << expected;
  // Needs --force (link speed) / address not public.
  EXPECT_EQ(std::ranges::find(names, "NVBAUDRATE"), names.end());
  EXPECT_EQ(std::ranges::find(names, "NVDEADZONE"), names.end());
  FakeCard card(db());
  const Profile p = save(card, db(), {});
  EXPECT_EQ(p.settings.size(), names.size());
  // A saved default card validates (its values are the manual's defaults).
  EXPECT_FALSE(has_errors(validate(load(to_yaml(p, db())), db()))) << dump(validate(p, db()));
}

TEST(ProfileSave, RefusesReadOnlyAndUnknownNames) {
  FakeCard card(db());
  EXPECT_THROW(save(card, db(), {"BUSV"}), ProfileError);
  EXPECT_THROW(save(card, db(), {"NVBRAKEON"}), i20::params::UnknownParameter);
  EXPECT_EQ(card.read_calls, 0);
}

TEST(ProfileSave, CardErrorsPropagate) {
  FakeCard card(db());
  card.fail_reads_of = {"NVKQP"};
  EXPECT_THROW(save(card, db(), {"NVKQP"}), i20::Error);
}
