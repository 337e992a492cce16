// SPDX-License-Identifier: GPL-2.0-or-later
// The strict loader of params/faults.yaml, and the compiled-in copy.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "faults/fault_table.hpp"
#include "table_yaml.hpp"

using namespace i20::faults;
using namespace i20::faults::testing;

namespace {

std::filesystem::path source_file() {
  const char* src = std::getenv("I20_SOURCE_DIR");
  return std::filesystem::path(src ? src : ".") / "params" / "faults.yaml";
}

// Header is 2 lines, "fault:" line 3, first bit at line 4 (11 lines per bit).
std::string table(const std::string& fault_bits, const std::string& status_bits = "") {
  return "schema: 1\ndevice: 8I20\nfault:\n" + fault_bits + "status:\n" +
         (status_bits.empty() ? bit(0, "status-zero") : status_bits);
}

}  // namespace

TEST(FaultLoader, AcceptsAMinimalTable) {
  const auto t = FaultTable::load_string(table(bit(1, "one") + bit(0, "zero")), "ok.yaml");
  ASSERT_EQ(t.bits(Register::Fault).size(), 2u);
  EXPECT_EQ(t.bits(Register::Fault)[0].bit, 0u);  // sorted by bit
  EXPECT_EQ(t.bits(Register::Fault)[1].origin, "ok.yaml:4");
  EXPECT_TRUE(t.notes(Register::Fault).empty());
}

TEST(FaultLoader, RejectsBitsAbove15) {
  EXPECT_TRUE(rejected_at(table(bit(16, "x")), 4, "bit 16 is outside the 16-bit register"));
  EXPECT_TRUE(rejected_at(table(bit(0, "a") + bit(99, "b")), 15, "bit 99 is outside"));
}

TEST(FaultLoader, RejectsNegativeOrNonNumericBits) {
  auto yaml = table(bit(0, "x"));
  yaml.replace(yaml.find("bit: 0"), 6, "bit: -1");
  EXPECT_TRUE(rejected_at(yaml, 4, "outside the 16-bit register"));
  yaml.replace(yaml.find("bit: -1"), 7, "bit: two");
  EXPECT_TRUE(rejected_at(yaml, 4, "'bit' must be a whole number 0..15, not 'two'"));
}

TEST(FaultLoader, RejectsDuplicateBits) {
  EXPECT_TRUE(
      rejected_at(table(bit(1, "a") + bit(1, "b")), 15, "duplicate FAULT bit 1 (first at bad.yaml:4)"));
}

TEST(FaultLoader, TheSameBitNumberInBothRegistersIsFine) {
  // FAULT and STATUS are two registers (manual, FAULT and STATUS bit tables): bit 0 of each
  // is its own bit, loaded into its own register, not a duplicate and not one overwriting
  // the other.
  const auto t = FaultTable::load_string(table(bit(0, "a"), bit(0, "b")), "ok.yaml");
  const BitInfo* fault = t.find(Register::Fault, 0u);
  const BitInfo* status = t.find(Register::Status, 0u);
  ASSERT_NE(fault, nullptr);
  ASSERT_NE(status, nullptr);
  EXPECT_EQ(fault->slug, "a");
  EXPECT_EQ(fault->reg, Register::Fault);
  EXPECT_EQ(status->slug, "b");
  EXPECT_EQ(status->reg, Register::Status);
  EXPECT_EQ(t.find(Register::Status, "a"), nullptr) << "a FAULT bit's name does not leak into STATUS";
}

TEST(FaultLoader, RejectsDuplicateSlugsEvenAcrossRegisters) {
  EXPECT_TRUE(
      rejected_at(table(bit(1, "same", "", "ONE") + bit(2, "same", "", "TWO")), 17, "duplicate slug 'same'"));
  // "status:" is line 15, its bit line 16, the slug line 18.
  EXPECT_TRUE(
      rejected_at(table(bit(1, "same", "", "ONE"), bit(2, "same", "", "TWO")), 18, "duplicate slug 'same'"));
}

TEST(FaultLoader, RejectsDuplicateNames) {
  EXPECT_TRUE(rejected_at(table(bit(1, "a", "", "X") + bit(2, "b", "", "X")), 16, "duplicate name 'X'"));
}

TEST(FaultLoader, RejectsDuplicateLinuxCncPins) {
  EXPECT_TRUE(rejected_at(
      table(bit(1, "a", "    linuxcnc_pin: fault.x\n") + bit(2, "b", "    linuxcnc_pin: FAULT.X\n")), 27,
      "duplicate linuxcnc_pin 'FAULT.X' (first at bad.yaml:15)"));
}

TEST(FaultLoader, ABitMayReuseItsOwnSpelling) {
  // Name MODULE with slug module is one bit spelled twice, not a clash.
  EXPECT_NO_THROW(FaultTable::load_string(table(bit(11, "module", "", "MODULE")), "ok.yaml"));
}

TEST(FaultLoader, RejectsUnknownKeysNamingTheAllowedOnes) {
  EXPECT_TRUE(
      rejected_at(table(bit(1, "a", "    colour: red\n")), 15, "unknown key 'colour' in a FAULT bit"));
  EXPECT_TRUE(rejected_at("schema: 1\nextra: 1\n" + table(bit(1, "a")).substr(10), 2, "unknown key 'extra'"));
}

TEST(FaultLoader, RejectsAKeyGivenTwice) {
  EXPECT_TRUE(rejected_at(table(bit(1, "a", "    sticky: false\n")), 15, "key 'sticky' given twice"));
}

TEST(FaultLoader, RejectsMissingKeysAndEmptyAdvice) {
  auto yaml = table(bit(1, "a"));
  yaml.erase(yaml.find("    checks: [a check]\n"), 22);
  EXPECT_TRUE(rejected_at(yaml, 4, "lacks required key 'checks'"));
  yaml = table(bit(1, "a"));
  yaml.replace(yaml.find("[a check]"), 9, "[]");
  EXPECT_TRUE(rejected_at(yaml, 10, "'checks' must be a non-empty list"));
}

TEST(FaultLoader, RejectsBadValues) {
  auto yaml = table(bit(1, "a"));
  yaml.replace(yaml.find("severity: fault"), 15, "severity: scary");
  EXPECT_TRUE(rejected_at(yaml, 7, "'severity' must be fault, warning or info"));
  yaml = table(bit(1, "a"));
  yaml.replace(yaml.find("sticky: true"), 12, "sticky: yes");
  EXPECT_TRUE(rejected_at(yaml, 11, "'sticky' must be true or false"));
  EXPECT_TRUE(rejected_at(table(bit(1, "Bad_Slug")), 6, "'slug' must be lower case"));
  EXPECT_TRUE(rejected_at(table(bit(1, "a", "", "lower")), 5, "'name' must be upper case"));
}

TEST(FaultLoader, OnlyFaultBitsCanBeMaskable) {
  auto status = bit(0, "s");
  status.replace(status.find("maskable: false"), 15, "maskable: true");
  EXPECT_TRUE(rejected_at(table(bit(1, "a"), status), 24, "only FAULT bits can be maskable"));
}

TEST(FaultLoader, RejectsWrongSchemaDeviceAndShape) {
  auto yaml = table(bit(1, "a"));
  EXPECT_TRUE(rejected_at("schema: 2" + yaml.substr(9), 1, "'schema: 1' is required"));
  EXPECT_TRUE(rejected_at("schema: 1\ndevice: 7I64" + yaml.substr(22), 2, "not the 8I20"));
  EXPECT_TRUE(rejected_at("schema: 1\nfault: []\nstatus: []\n", 2, "'fault' must be a non-empty list"));
  EXPECT_TRUE(rejected_at("- 1\n", 1, "expected a map"));
  EXPECT_TRUE(rejected_at("schema: 1\nfault: [\n", 3, "not valid YAML"));
}

TEST(FaultLoader, ReadsNotesPerRegister) {
  const auto t =
      FaultTable::load_string("notes:\n  fault: [clear with CLEARFAULT]\n" + table(bit(1, "a")), "ok");
  ASSERT_EQ(t.notes(Register::Fault).size(), 1u);
  EXPECT_TRUE(t.notes(Register::Status).empty());
  EXPECT_TRUE(rejected_at("notes:\n  other: [x]\n" + table(bit(1, "a")), 2, "unknown key 'other' in notes"));
}

TEST(FaultLoader, MissingFileSaysSo) {
  try {
    FaultTable::load_file("/nonexistent/faults.yaml");
    FAIL();
  } catch (const FaultFileError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/faults.yaml: cannot open"), std::string::npos);
  }
}

// A fault table is a few KB; a directory or a huge file is refused before parsing.
TEST(FaultLoader, RefusesDirectoriesAndHugeFilesBeforeParsing) {
  const auto dir = std::filesystem::temp_directory_path() / "i20-fault-loader-bounds";
  std::filesystem::create_directories(dir);
  const auto huge = dir / "faults.yaml";
  std::ofstream(huge) << "";
  std::filesystem::resize_file(huge, 2u << 20);
  try {
    FaultTable::load_file(huge);
    FAIL();
  } catch (const FaultFileError& e) {
    EXPECT_EQ(
        std::string(e.what()),
        huge.string() +
            ": the fault table is larger than 1048576 bytes, the limit for it (a real one is a few KB)");
  }
  try {
    FaultTable::load_file(dir);
    FAIL();
  } catch (const FaultFileError& e) {
    EXPECT_EQ(std::string(e.what()), dir.string() + ": is a directory, not a fault table");
  }
  std::filesystem::remove_all(dir);
}

TEST(FaultBuiltin, CompiledInCopyEqualsParamsFaultsYaml) {
  ASSERT_NE(std::getenv("I20_SOURCE_DIR"), nullptr) << "run under ctest";
  const auto file = FaultTable::load_file(source_file());
  const auto& builtin = FaultTable::builtin();
  for (auto reg : {Register::Fault, Register::Status}) {
    EXPECT_EQ(file.notes(reg), builtin.notes(reg));
    const auto& a = file.bits(reg);
    const auto& b = builtin.bits(reg);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      SCOPED_TRACE(a[i].name);
      EXPECT_EQ(a[i].bit, b[i].bit);
      EXPECT_EQ(a[i].name, b[i].name);
      EXPECT_EQ(a[i].slug, b[i].slug);
      EXPECT_EQ(a[i].linuxcnc_pin, b[i].linuxcnc_pin);
      EXPECT_EQ(a[i].severity, b[i].severity);
      EXPECT_EQ(a[i].meaning, b[i].meaning);
      EXPECT_EQ(a[i].causes, b[i].causes);
      EXPECT_EQ(a[i].checks, b[i].checks);
      EXPECT_EQ(a[i].sticky, b[i].sticky);
      EXPECT_EQ(a[i].maskable, b[i].maskable);
      EXPECT_EQ(a[i].clears_while_cause_persists, b[i].clears_while_cause_persists);
      EXPECT_EQ(a[i].source, b[i].source);
      ASSERT_EQ(a[i].live_check.has_value(), b[i].live_check.has_value());
      if (a[i].live_check) {
        const auto &x = *a[i].live_check, &y = *b[i].live_check;
        EXPECT_EQ(x.measured, y.measured);
        EXPECT_EQ(x.compare, y.compare);
        EXPECT_EQ(x.threshold_param, y.threshold_param);
        EXPECT_EQ(x.threshold_value, y.threshold_value);
        EXPECT_EQ(x.fixed, y.fixed);
        EXPECT_EQ(x.unit, y.unit);
        EXPECT_EQ(x.advice, y.advice);
        EXPECT_EQ(x.status_bit, y.status_bit);
        EXPECT_EQ(x.status_set, y.status_set);
        EXPECT_EQ(x.status_clear, y.status_clear);
      }
      // Same line in both: the compiled copy is the file byte for byte up to there.
      EXPECT_EQ(a[i].origin.substr(a[i].origin.rfind(':')), b[i].origin.substr(b[i].origin.rfind(':')));
    }
  }
}

TEST(FaultBuiltin, CarriesItsSourceName) {
  EXPECT_EQ(FaultTable::builtin().source(), "params/faults.yaml");
}

// hostmot2 names every bit after its register (LinuxCNC sserial.h, hm2_8i20_params;
// docs/facts.md s4): a FAULT bit's pin is fault.NAME, a STATUS bit's status.NAME.
TEST(FaultLoader, APinNamesItsOwnRegister) {
  try {
    FaultTable::load_string(table(bit(1, "a", "    linuxcnc_pin: status.x\n")), "bad.yaml");
    FAIL() << "a FAULT bit with a status pin loaded";
  } catch (const FaultFileError& e) {
    EXPECT_NE(std::string(e.what()).find("must be fault.NAME, not 'status.x'"), std::string::npos)
        << e.what();
  }
  for (const auto& b : FaultTable::builtin().bits(Register::Status)) {
    if (!b.linuxcnc_pin.empty()) {
      EXPECT_EQ(b.linuxcnc_pin.rfind("status.", 0), 0u) << b.name;
    }
  }
}
