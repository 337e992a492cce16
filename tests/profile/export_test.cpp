// SPDX-License-Identifier: GPL-2.0-or-later
// Profiles into LinuxCNC: the HAL names and units hostmot2 uses for the 8I20's NV parameters
// (LinuxCNC sserial.h hm2_8i20_globals, sserial(9), setsserial(9); docs/facts.md s2, s6), and
// the round trip profile -> exported text -> values.
#include "profile/export.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "profile/error.hpp"
#include "profile/loader.hpp"
#include "profile/validate.hpp"
#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;

namespace {

const std::string kDevice = "hm2_7i96s.0.8i20.0.0";

ExportOptions options(const std::string& device = kDevice) {
  return {device, "test.yaml"};
}

bool has_line(const std::string& text, const std::string& line) {
  return text.find("\n" + line + "\n") != std::string::npos;
}

// Every NV value the manual's PARAMETERS table lets a profile set, with a distinct value.
const char* kAllNv = R"(  NVMAXCURRENT: 7.5 A
  NVBAUDRATE: 9
  NVKQP: 60
  NVKQI: 150000
  NVKQIL: 1000
  NVKDP: 61
  NVKDI: 200001
  NVKDIL: 1001
  NVBUSUNDERV: 40 V
  NVBUSUNDERVMAX: 45 V
  NVBUSOVERV: 380 V
  NVBRAKEONV: 370 V
  NVBRAKEOFFV: 350 V
)";

}  // namespace

TEST(ProfileExport, HostmotNamesAreTheDriversAndMapToTheNvAddresses) {
  // sserial.h hm2_8i20_globals: name -> EEPROM address. The names come from the database's
  // aliases (params/8i20.yaml); this checks them, and their addresses, against the driver.
  const std::map<std::string, std::uint16_t> driver = {
      {"nvmaxcurrent", 2}, {"nvbusundervmax", 36}, {"nvbusundervmin", 34}, {"nvbusoverv", 38},
      {"nvbrakeonv", 40},  {"nvbrakeoffv", 42},    {"nvrembaudrate", 6},   {"nvkqp", 10},
      {"nvkqihi", 14},     {"nvkqilo", 12},        {"nvkqil", 16},         {"nvkdp", 18},
      {"nvkdihi", 22},     {"nvkdilo", 20},        {"nvkdil", 24}};
  std::set<std::string> seen;
  for (const auto& p : hostmot2_nv_parameters(db())) {
    const std::string name(p.hal_name);
    ASSERT_TRUE(driver.count(name)) << name << " is not a hostmot2 8I20 NV parameter";
    seen.insert(name);
    const auto& param = db().get(p.db_name);
    EXPECT_TRUE(param.is_nv()) << name;
    ASSERT_TRUE(param.address) << name;
    // A high half sits 2 bytes above the 32-bit value's address (little endian, s1).
    const unsigned offset = p.part == HalPart::High16 ? 2 : 0;
    EXPECT_EQ(*param.address + offset, driver.at(name)) << name << " -> " << p.db_name;
    EXPECT_EQ(param.width_bits, p.part == HalPart::Whole ? 16u : 32u) << name;
  }
  EXPECT_EQ(seen.size(), driver.size()) << "every hostmot2 NV parameter has exactly one entry";
}

TEST(ProfileExport, HalLinesCarryRawEepromWords) {
  const Profile p = load(with_params("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 170 V\n  NVMAXCURRENT: 7.5 A\n"));
  const std::string text = hal_text(p, db(), options());
  // hostmot2's NV parameters are u32 EEPROM words: 10 mV and 10 mA steps, not volts/amps
  // (setsserial(9): "set hm2_8i20.001f.nvmaxcurrent 750" is 7.5 A).
  EXPECT_TRUE(has_line(text, "setp hm2_7i96s.0.8i20.0.0.nvbrakeonv 19000")) << text;
  EXPECT_TRUE(has_line(text, "setp hm2_7i96s.0.8i20.0.0.nvbrakeoffv 17000")) << text;
  EXPECT_TRUE(has_line(text, "setp hm2_7i96s.0.8i20.0.0.nvmaxcurrent 750")) << text;
  // The engineering value is in a comment for the reader, never in the setp line.
  EXPECT_TRUE(has_line(text, "# NVBRAKEONV = 19000 (190.00 V)")) << text;
  for (std::size_t at = 0; (at = text.find('\n', at)) != std::string::npos; ++at) {
    const std::string next = text.substr(at + 1, text.find('\n', at + 1) - at - 1);
    EXPECT_TRUE(next.empty() || next[0] == '#' || next.rfind("setp ", 0) == 0) << "stray line: " << next;
  }
}

TEST(ProfileExport, ThirtyTwoBitGainsBecomeLowAndHighHalves) {
  const Profile p = load(with_params("  NVKQI: 150000\n  NVKDI: 0x12345678\n"));
  const std::string text = hal_text(p, db(), options());
  // 150000 = 2 * 65536 + 18928: nvkqilo holds bits 0-15, nvkqihi bits 16-31.
  EXPECT_TRUE(has_line(text, "setp hm2_7i96s.0.8i20.0.0.nvkqilo 18928")) << text;
  EXPECT_TRUE(has_line(text, "setp hm2_7i96s.0.8i20.0.0.nvkqihi 2")) << text;
  EXPECT_TRUE(has_line(text, "setp hm2_7i96s.0.8i20.0.0.nvkdilo 22136")) << text;  // 0x5678
  EXPECT_TRUE(has_line(text, "setp hm2_7i96s.0.8i20.0.0.nvkdihi 4660")) << text;   // 0x1234
  EXPECT_LT(text.find("nvkqilo"), text.find("nvkqihi")) << "low half first, like the addresses";
}

TEST(ProfileExport, SetsserialLinesLoadOneWriteEachAndUnload) {
  const Profile p = load(with_params("  NVBRAKEONV: 190 V\n  NVKQI: 150000\n"));
  const std::string text = setsserial_text(p, db(), options("hm2_8i20.001f"));
  EXPECT_TRUE(has_line(text, "loadrt setsserial cmd=\"set hm2_8i20.001f.nvbrakeonv 19000\"")) << text;
  EXPECT_TRUE(has_line(text, "loadrt setsserial cmd=\"set hm2_8i20.001f.nvkqilo 18928\"")) << text;
  EXPECT_TRUE(has_line(text, "loadrt setsserial cmd=\"set hm2_8i20.001f.nvkqihi 2\"")) << text;
  std::size_t loads = 0, unloads = 0;
  for (std::size_t at = 0; (at = text.find("\nloadrt setsserial", at)) != std::string::npos; ++at) ++loads;
  for (std::size_t at = 0; (at = text.find("\nunloadrt setsserial\n", at)) != std::string::npos; ++at)
    ++unloads;
  EXPECT_EQ(loads, 3u);
  EXPECT_EQ(unloads, loads) << "each load is undone so the next one can load";
}

TEST(ProfileExport, RoundTripGivesBackEveryNvValue) {
  const Profile p = load(with_params(kAllNv));
  std::map<std::string, std::int64_t> expected;
  for (const auto& s : p.settings) expected[s.name] = s.raw;
  for (const auto& text : {hal_text(p, db(), options()), setsserial_text(p, db(), options())})
    EXPECT_EQ(parse_exported(text, kDevice, db()), expected) << text;
  // Another device's lines are not this card's values.
  EXPECT_TRUE(parse_exported(hal_text(p, db(), options("hm2_7i96s.0.8i20.0.1")), kDevice, db()).empty());
}

TEST(ProfileExport, WorkingOnlyEntriesAreSkippedAndSaidSo) {
  const Profile p =
      load(with_params("  BRAKEONV: 300 V\n  NVBRAKEONV: {value: 190 V}\n  NVKQP: {value: 50, "
                       "target: both}\n  NVDEADZONE: 10\n"));
  const auto values = hostmot2_values(p, db());
  std::set<std::string> names;
  for (const auto& s : values.settings) names.insert(s.hal_name);
  EXPECT_EQ(names, (std::set<std::string>{"nvbrakeonv", "nvkqp"}));
  ASSERT_EQ(values.skipped.size(), 3u);  // BRAKEONV, KQP (working half of both), NVDEADZONE
  const std::string text = hal_text(p, db(), options());
  EXPECT_NE(text.find("# skipped: BRAKEONV: a working (live) value"), std::string::npos) << text;
  EXPECT_NE(text.find("# skipped: NVDEADZONE: hostmot2 has no parameter"), std::string::npos) << text;
}

TEST(ProfileExport, NothingToExportIsAnError) {
  const Profile p = load(with_params("  BRAKEONV: 300 V\n"));
  EXPECT_THROW(hal_text(p, db(), options()), ProfileError);
}

TEST(ProfileExport, DeviceNamesAreHostmotNamesOnly) {
  EXPECT_NO_THROW(check_hal_device("hm2_7i96s.0.8i20.0.0"));
  EXPECT_NO_THROW(check_hal_device("hm2_7i92t.1.8i20.1.7"));
  EXPECT_NO_THROW(check_hal_device("hm2_8i20.001f"));
  // Anything that could break out of the halcmd line or the quoted setsserial argument.
  for (const char* bad : {"", "hm2_7i96s.0.8i20.0", "hm2_7i96s.0.8i20.0.0 ", "x\" ; rm",
                          "hm2_7i96s.0.7i76.0.0", "hm2_8i20.001F.", "hm2_7i96s.0.8i20.0.0\nsetp"}) {
    EXPECT_THROW(check_hal_device(bad), i20::Error) << bad;
    const Profile p = load(with_params("  NVKQP: 50\n"));
    EXPECT_THROW(hal_text(p, db(), options(bad)), i20::Error) << bad;
  }
}

TEST(ProfileExport, ParsingRefusesWhatItCannotTrust) {
  EXPECT_THROW(parse_exported("setp hm2_7i96s.0.8i20.0.0.nvkqilo 5\n", kDevice, db()),
               i20::Error);  // no hi half
  EXPECT_THROW(parse_exported("setp hm2_7i96s.0.8i20.0.0.nvfoo 5\n", kDevice, db()), i20::Error);
  EXPECT_THROW(parse_exported("setp hm2_7i96s.0.8i20.0.0.nvkqp 70000\n", kDevice, db()),
               i20::Error);  // > 16 bit
  EXPECT_THROW(parse_exported("setp hm2_7i96s.0.8i20.0.0.nvkqp 5x\n", kDevice, db()), i20::Error);
  const auto values =
      parse_exported("# comment\nloadrt hostmot2\nsetp hm2_7i96s.0.8i20.0.0.nvkqp 0x32\n", kDevice, db());
  EXPECT_EQ(values, (std::map<std::string, std::int64_t>{{"NVKQP", 50}}));
}

// Issue 20, item 4: `profile export --setsserial line-120v` wrote nvbusundervmin 9000 and left
// the card's nvbusundervmax (40 V on the simulator) below it. The shipped line profiles now
// write both words, the low one below the high one (docs/facts.md s2).
TEST(ProfileExport, TheShippedLineProfilesWriteTheUnderVoltagePairInOrder) {
  const char* root = std::getenv("I20_SOURCE_DIR");
  for (const char* name : {"line-120v.yaml", "line-240v.yaml", "bench-48v.yaml"}) {
    SCOPED_TRACE(name);
    const Profile p =
        load_profile_file(std::filesystem::path(root ? root : ".") / "profiles" / name, db());
    const auto values = parse_exported(setsserial_text(p, db(), options()), kDevice, db());
    ASSERT_TRUE(values.contains("NVBUSUNDERV"));
    ASSERT_TRUE(values.contains("NVBUSUNDERVMAX")) << "the high word is written, not left as the card has it";
    EXPECT_LT(values.at("NVBUSUNDERV"), values.at("NVBUSUNDERVMAX"));
  }
  // A profile that raises the low word alone is not valid offline, so export refuses it.
  const auto findings = validate(load(with_params("  NVBUSUNDERV: 90 V\n")), db());
  EXPECT_TRUE(has_rule(findings, "undervoltage-pair-unknown", Severity::Error)) << dump(findings);
}
