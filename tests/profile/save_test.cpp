// SPDX-License-Identifier: GPL-2.0-or-later
// Saving a card into a profile: engineering units, provenance comments, loads back exactly.
#include "profile/save.hpp"

#include <gtest/gtest.h>

#include <chrono>

#include "profile/validate.hpp"
#include "profile/writer.hpp"
#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;

namespace {

// What a default card holds: every writable parameter at its default (working ones at their
// NV twin's), NVMAXCURRENT 10 A (the manual gives no default).
RawValues default_card() {
  RawValues values;
  for (const auto& p : db().all()) {
    auto value = p.default_value;
    if (!value && !p.twin.empty()) value = db().get(p.twin).default_value;
    values[p.name] = value.value_or(0);
  }
  values["NVMAXCURRENT"] = values["MAXCURRENT"] = 1000;
  // No published factory value; the simulator's, above NVBUSUNDERV as the pair must be.
  values["NVBUSUNDERVMAX"] = values["BUSUNDERVMAX"] = 4000;
  return values;
}

Profile save(RawValues values, const std::vector<std::string>& names, const SaveOptions& options = {}) {
  const auto wanted = canonical_save_names(names.empty() ? default_save_names(db()) : names, db());
  return profile_from_values(values, wanted, db(), "fake 8I20 unit 0x00C0FFEE", options);
}

}  // namespace

TEST(ProfileSave, ReadsTheNamedParametersWithProvenance) {
  auto card = default_card();
  card["NVBRAKEONV"] = 19000;
  SaveOptions options;
  options.name = "cell-3 x axis";
  options.when = std::chrono::system_clock::time_point{std::chrono::seconds{1700000000}};
  const Profile p = save(card, {"nvbrakeonv", "NVKQP", "KQP", "NVKQP"}, options);
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
  const Profile p = save(default_card(), {});
  EXPECT_EQ(p.settings.size(), names.size());
  // A saved default card validates (its values are the manual's defaults).
  EXPECT_FALSE(has_errors(validate(load(to_yaml(p, db())), db()))) << dump(validate(p, db()));
}

TEST(ProfileSave, RefusesReadOnlyAndUnknownNames) {
  EXPECT_THROW(canonical_save_names({"BUSV"}, db()), ProfileError);
  EXPECT_THROW(canonical_save_names({"NVBRAKEON"}, db()), i20::params::UnknownParameter);
}

TEST(ProfileSave, AValueThatWasNotReadIsAnError) {
  auto card = default_card();
  card.erase("NVKQP");
  EXPECT_THROW(save(card, {"NVKQP"}), ProfileError);
}
