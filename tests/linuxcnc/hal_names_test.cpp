// SPDX-License-Identifier: GPL-2.0-or-later
// The bldc table against LinuxCNC 2.9's bldc itself: tests/linuxcnc/data/bldc-halrun-2.9.txt
// lists every pin and param halrun showed for 23 cfg strings.
#include "linuxcnc/hal_names.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>

#include "build_paths.hpp"
#include "error/error.hpp"

using namespace i20::linuxcnc;

namespace {

struct Recorded {
  std::string cfg;
  BldcNames names;
};

// "# loadrt bldc cfg=a,b" starts a group; "pin bldc.N.x" / "param bldc.N.x" belong to the
// Nth cfg string of the group.
std::vector<Recorded> recorded() {
  std::ifstream in(i20::test::source_dir() / "tests/linuxcnc/data/bldc-halrun-2.9.txt");
  std::vector<Recorded> out;
  std::size_t group_start = 0;
  for (std::string line; std::getline(in, line);) {
    const std::string start = "# loadrt bldc cfg=";
    if (line.rfind(start, 0) == 0) {
      group_start = out.size();
      std::stringstream cfgs(line.substr(start.size()));
      for (std::string cfg; std::getline(cfgs, cfg, ',');) out.push_back({cfg, {}});
      continue;
    }
    if (line.empty() || line[0] == '#') continue;
    std::stringstream words(line);
    std::string kind, name;
    words >> kind >> name;
    const auto first_dot = name.find('.'), second_dot = name.find('.', first_dot + 1);
    const auto index = std::stoul(name.substr(first_dot + 1, second_dot - first_dot - 1));
    auto& r = out.at(group_start + index);
    (kind == "pin" ? r.names.pins : r.names.params).insert(name.substr(second_dot + 1));
  }
  return out;
}

}  // namespace

TEST(HalNames, BldcCfgMakesExactlyThePinsLinuxcnc29Makes) {
  const auto cases = recorded();
  ASSERT_EQ(cases.size(), 21u);
  for (const auto& c : cases) {
    const auto ours = HalNames::builtin().bldc_names(c.cfg);
    EXPECT_EQ(ours.pins, c.names.pins) << "pins of cfg=" << c.cfg;
    EXPECT_EQ(ours.params, c.names.params) << "params of cfg=" << c.cfg;
  }
}

TEST(HalNames, OnlyTheFirstEightCfgCharactersAndKnownLettersCount) {
  const auto& n = HalNames::builtin();
  EXPECT_EQ(n.bldc_letters("qhnxq"), "qh");                   // `n` (documented) and repeats are ignored
  EXPECT_FALSE(n.bldc_names("xxxxxxxxq").has("lead-angle"));  // q is the 9th character
  EXPECT_TRUE(n.bldc_names("xxxxxxxq").has("lead-angle"));
  EXPECT_EQ(n.bldc_max_instances(), 8);
  EXPECT_EQ(n.bldc_default("lead-angle"), 90.0);
  EXPECT_EQ(n.bldc_default("initvalue"), 0.2);
}

TEST(HalNames, EightI20BitPinsComeFromTheFaultTable) {
  const auto& n = HalNames::builtin();
  ASSERT_EQ(n.i20_fault_pins().size(), 13u);  // sserial.h's 8I20 table: 13 fault bits
  EXPECT_EQ(n.i20_fault_pins().front(), "fault.watchdog");
  EXPECT_EQ(n.i20_fault_pins().back(), "fault.framingr");
  EXPECT_EQ(n.i20_status_pins().size(), 9u);
}

TEST(HalNames, EveryObsoleteEightI20NameHasAReplacement) {
  const auto& n = HalNames::builtin();
  for (const char* old :
       {"amp_enable", "max_current", "serial_number", "voltage", "temp", "fault", "status", "comms"}) {
    const auto* o = n.obsolete_8i20(old);
    ASSERT_NE(o, nullptr) << old;
    EXPECT_FALSE(o->replacement.empty()) << old;
  }
  EXPECT_EQ(n.obsolete_8i20("angle"), nullptr);
  EXPECT_NE(n.obsolete_8i20("temp")->replacement.find("card-temp"), std::string::npos);
}

TEST(HalNames, RejectsADataFileOfTheWrongShape) {
  EXPECT_THROW(HalNames::load_string("schema: 1\n", "x.yaml"), i20::UsageError);
  EXPECT_THROW(HalNames::load_string("schema: [\n", "x.yaml"), i20::UsageError);
}
