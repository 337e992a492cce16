// SPDX-License-Identifier: GPL-2.0-or-later
// The profile schema and its strict loader: errors name file, line, key and rule.
#include "profile/loader.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "profile/writer.hpp"
#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;

TEST(ProfileLoader, ReadsEngineeringUnitsAndRawGains) {
  const Profile p = load(R"(schema: 1
name: bench
parameters:
  NVMAXCURRENT: 7.5 A
  NVBRAKEONV: 190 V
  nvbrakeoffv: 170V
  NVKQP: 50
  NVKQI: 150000
)");
  ASSERT_EQ(p.settings.size(), 5u);
  EXPECT_EQ(p.settings[0].name, "NVMAXCURRENT");
  EXPECT_EQ(p.settings[0].raw, 750);             // 10 mA units (manual, MAXCURRENT)
  EXPECT_EQ(p.settings[1].raw, 19000);           // 10 mV units: the manual's 120 V example
  EXPECT_EQ(p.settings[2].name, "NVBRAKEOFFV");  // case-insensitive, database spelling
  EXPECT_EQ(p.settings[2].raw, 17000);
  EXPECT_EQ(p.settings[3].raw, 50);
  EXPECT_EQ(p.settings[4].raw, 150000);
  EXPECT_EQ(p.settings[0].line, 4);
  EXPECT_EQ(p.where(p.settings[4]), "test.yaml:8");
}

TEST(ProfileLoader, ReadsMetadata) {
  const Profile p = load(R"(name: axis-x
description: X axis of the router
motor:
  make: Acme
  model: AC-400
  continuous_current: 2.7 A
  peak_current: 8100 mA
  phase_resistance: 1.9 ohm
  phase_inductance: 6.2 mH
supply:
  description: 240 V line, bridge rectifier, 450 V capacitors
  bus_voltage: 340 V
notes: |
  first line
  second line
parameters:
  NVMAXCURRENT: 8 A
)");
  EXPECT_EQ(p.name, "axis-x");
  EXPECT_EQ(p.motor.make, "Acme");
  EXPECT_EQ(p.motor.model, "AC-400");
  EXPECT_DOUBLE_EQ(*p.motor.continuous_current_a, 2.7);
  EXPECT_DOUBLE_EQ(*p.motor.peak_current_a, 8.1);
  EXPECT_DOUBLE_EQ(*p.motor.phase_resistance_ohm, 1.9);
  EXPECT_NEAR(*p.motor.phase_inductance_h, 6.2e-3, 1e-12);
  EXPECT_DOUBLE_EQ(*p.supply.bus_voltage_v, 340.0);
  EXPECT_EQ(p.notes, "first line\nsecond line");
}

TEST(ProfileLoader, SupplyMayBeJustADescription) {
  const Profile p = load(with_params("  NVKQP: 50\n", "supply: 48 V bench supply\n"));
  EXPECT_EQ(p.supply.description, "48 V bench supply");
  EXPECT_FALSE(p.supply.bus_voltage_v);
}

// Every free text a profile holds is printed somewhere (show, diff, the console), so a
// control character is refused in each of them, whichever YAML form carries it. The
// short form of supply once skipped the check; the fuzzer found it when the saved copy
// would not load again.
TEST(ProfileLoader, ControlCharactersAreRefusedInEveryTextField) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"name: \"a\\x01b\"\nparameters:\n  NVKQP: 50\n", "name"},
      {with_params("  NVKQP: 50\n", "description: \"a\\x1bb\"\n"), "description"},
      {with_params("  NVKQP: 50\n", "supply: \"48 V\\x0f\"\n"), "supply"},
      {with_params("  NVKQP: 50\n", "supply: {description: \"x\\x01\"}\n"), "description"},
      {with_params("  NVKQP: 50\n", "motor: {make: \"x\\x01\"}\n"), "make"},
      {with_params("  NVKQP: 50\n", "motor: {model: \"x\\r\"}\n"), "model"},
      {with_params("  NVKQP: 50\n", "origin: {card: \"x\\x01\"}\n"), "card"},
      {with_params("  NVKQP: 50\n", "notes: \"x\\x07\"\n"), "notes"},
  };
  for (const auto& [text, key] : cases) {
    SCOPED_TRACE(text);
    const auto e = load_error(text);
    EXPECT_EQ(e.key(), key);
    EXPECT_NE(std::string(e.what()).find("control character"), std::string::npos) << e.what();
  }
}

TEST(ProfileLoader, TargetsResolveToCells) {
  const auto& d = db();
  // Default: the space the key names.
  Profile p = load(with_params("  NVKQP: 50\n  KDP: 50\n"));
  EXPECT_EQ(cells_of(p, p.settings[0], d), std::vector<std::string>{"NVKQP"});
  EXPECT_EQ(cells_of(p, p.settings[1], d), std::vector<std::string>{"KDP"});
  // Profile-wide target, overridden per entry.
  p = load(
      with_params("  NVKQP: 50\n  NVKDP: {value: 50, target: both}\n  NVKQI: {raw: 150000, target: nv}\n",
                  "target: working\n"));
  EXPECT_EQ(cells_of(p, p.settings[0], d), std::vector<std::string>{"KQP"});
  EXPECT_EQ(cells_of(p, p.settings[1], d), (std::vector<std::string>{"NVKDP", "KDP"}));
  EXPECT_EQ(cells_of(p, p.settings[2], d), std::vector<std::string>{"NVKQI"});
  // Working and NV halves of a pair may be set to different values.
  p = load(with_params("  NVBRAKEONV: 360 V\n  BRAKEONV: 350 V\n"));
  EXPECT_EQ(cell_writes(p, d).size(), 2u);
}

TEST(ProfileLoader, RawFormTakesCounts) {
  const Profile p = load(with_params("  NVMAXCURRENT: {raw: 750}\n  NVBRAKEONV: {raw: 0x4A38}\n"));
  EXPECT_EQ(p.settings[0].raw, 750);
  EXPECT_EQ(p.settings[1].raw, 19000);
}

TEST(ProfileLoader, RetargetAimsEveryEntry) {
  const Profile p = load(with_params("  NVKQP: 60\n  NVBRAKEONV: {value: 300 V, target: both}\n"));
  const Profile live = retarget(p, Memory::Working, db());
  const auto writes = cell_writes(live, db());
  ASSERT_EQ(writes.size(), 2u);
  EXPECT_EQ(writes[0].cell, "KQP");
  EXPECT_EQ(writes[1].cell, "BRAKEONV");
  // FAULTMASK has no EEPROM twin, so it cannot go to nv.
  EXPECT_THROW(retarget(load(with_params("  FAULTMASK: 0xFEFF\n")), Memory::Nv, db()), ProfileError);
}

TEST(ProfileLoader, RejectsUnknownParameterWithSuggestion) {
  const auto e = load_error(with_params("  NVKQP: 50\n  NVBRAKEONVV: 190 V\n"));
  EXPECT_EQ(e.where(), "test.yaml:4");
  EXPECT_EQ(e.key(), "NVBRAKEONVV");
  EXPECT_EQ(e.rule(), "unknown-parameter");
  EXPECT_NE(std::string(e.what()).find("NVBRAKEONV"), std::string::npos) << e.what();
  EXPECT_EQ(std::string(e.what()).rfind("test.yaml:4: NVBRAKEONVV: ", 0), 0u) << e.what();
}

TEST(ProfileLoader, RejectsBareNumbersForParametersWithUnits) {
  // 750 could be counts (7.5 A) or amperes: the loader makes the user say.
  auto e = load_error(with_params("  NVMAXCURRENT: 750\n"));
  EXPECT_EQ(e.rule(), "unit-required");
  EXPECT_EQ(e.where(), "test.yaml:3");
  EXPECT_EQ(e.key(), "NVMAXCURRENT");
  e = load_error(with_params("  NVBRAKEONV: 0x4A38\n"));
  EXPECT_EQ(e.rule(), "unit-required");
  e = load_error(with_params("  NVBRAKEONV: 4A38h\n"));
  EXPECT_EQ(e.rule(), "unit-required");
}

// Issue 20, item 3: the same parser as `i20 set`, so the same raw form and the same units.
TEST(ProfileLoader, RawCountsAreRawColonNAndUnitsAreSiCase) {
  const Profile p = load(with_params("  NVMAXCURRENT: raw:750\n  NVBRAKEONV: raw:0x4A38\n  NVKQP: raw:50\n"));
  EXPECT_EQ(p.settings[0].raw, 750);
  EXPECT_EQ(p.settings[1].raw, 0x4A38);
  EXPECT_EQ(p.settings[2].raw, 50);
  auto e = load_error(with_params("  NVMAXCURRENT: 750\n"));
  EXPECT_EQ(e.reason(), "a current needs its unit (750A, 750mA) or raw:750 for card counts (10 mA each)");
  e = load_error(with_params("  NVMAXCURRENT: 7.5 a\n"));
  EXPECT_EQ(e.rule(), "unit-required");
  EXPECT_EQ(e.reason(), "unit 'a' is not known; did you mean 'A'?");
  e = load_error(with_params("  NVBRAKEONV: 190 v\n"));
  EXPECT_EQ(e.reason(), "unit 'v' is not known; did you mean 'V'?");
  e = load_error("name: x\nmotor:\n  phase_inductance: 1.75mh\nparameters:\n  NVKQP: 50\n");
  EXPECT_EQ(e.rule(), "unit");
  EXPECT_EQ(e.reason(), "1.75mh: unit 'mh' is not known; did you mean 'mH'?");
  e = load_error("name: x\nmotor:\n  continuous_current: 2.7a\nparameters:\n  NVKQP: 50\n");
  EXPECT_EQ(e.reason(), "2.7a: unit 'a' is not known; did you mean 'A'?");
  e = load_error("name: x\nsupply:\n  bus_voltage: 48\nparameters:\n  NVKQP: 50\n");
  EXPECT_EQ(e.reason(), "48: a voltage needs its unit (48V, 48mV)");
  EXPECT_EQ(load_error(with_params("  NVMAXCURRENT: RAW:750\n")).rule(), "value");
}

TEST(ProfileLoader, RejectsBadValues) {
  EXPECT_EQ(load_error(with_params("  NVMAXCURRENT: 7.555 A\n")).rule(), "value");  // finer than 10 mA
  EXPECT_EQ(load_error(with_params("  NVBRAKEONV: 190 A\n")).rule(), "unit-required");
  EXPECT_EQ(load_error(with_params("  NVKQP: 50 V\n")).rule(), "value");
  EXPECT_EQ(load_error(with_params("  NVKQP: 1.5\n")).rule(), "value");
  EXPECT_EQ(load_error(with_params("  NVKQP: lots\n")).rule(), "value");
  EXPECT_EQ(load_error(with_params("  NVKQP: [1, 2]\n")).rule(), "schema");
  EXPECT_NE(std::string(load_error(with_params("  NVKQP:\n")).what()).find("has no value"),
            std::string::npos);
  EXPECT_EQ(load_error(with_params("  NVKQP: {value: 50, raw: 50}\n")).rule(), "schema");
  EXPECT_EQ(load_error(with_params("  NVKQP: {value: 50, when: now}\n")).rule(), "schema");
}

TEST(ProfileLoader, RejectsBadTargets) {
  auto e = load_error(with_params("  NVKQP: {value: 50, target: eeprom}\n"));
  EXPECT_EQ(e.rule(), "target");
  EXPECT_EQ(e.where(), "test.yaml:3");
  EXPECT_EQ(load_error(with_params("  NVKQP: 50\n", "target: live\n")).rule(), "target");
  // NVBAUDRATE has no working twin; FAULTMASK no EEPROM twin.
  e = load_error(with_params("  NVKQP: 50\n  NVBAUDRATE: {value: 9, target: both}\n"));
  EXPECT_EQ(e.rule(), "target");
  EXPECT_EQ(e.where(), "test.yaml:4");
  EXPECT_EQ(load_error(with_params("  FAULTMASK: {value: 0xFFFF, target: nv}\n")).rule(), "target");
}

TEST(ProfileLoader, RejectsDuplicates) {
  auto e = load_error(with_params("  NVKQP: 50\n  nvkqp: 60\n"));
  EXPECT_EQ(e.rule(), "duplicate");
  EXPECT_EQ(e.where(), "test.yaml:4");
  // "both" already writes BRAKEONV.
  e = load_error(with_params("  NVBRAKEONV: {value: 360 V, target: both}\n  BRAKEONV: 350 V\n"));
  EXPECT_EQ(e.rule(), "duplicate");
  EXPECT_EQ(e.where(), "test.yaml:4");
  EXPECT_EQ(load_error("name: a\nname: b\nparameters:\n  NVKQP: 50\n").rule(), "duplicate");
}

TEST(ProfileLoader, RejectsSchemaViolations) {
  auto e = load_error("name: x\nmotors: {}\nparameters:\n  NVKQP: 50\n");
  EXPECT_EQ(e.rule(), "schema");
  EXPECT_EQ(e.where(), "test.yaml:2");
  EXPECT_EQ(e.key(), "motors");
  EXPECT_EQ(load_error("parameters:\n  NVKQP: 50\n").rule(), "schema");  // no name
  EXPECT_EQ(load_error("name: x\n").rule(), "schema");                   // no parameters
  EXPECT_EQ(load_error("name: x\nparameters: {}\n").rule(), "schema");   // empty
  EXPECT_EQ(load_error("name: x\nschema: 2\nparameters:\n  NVKQP: 50\n").rule(), "schema");
  EXPECT_EQ(load_error("- just\n- a list\n").rule(), "schema");
  e = load_error("name: x\nmotor:\n  model: m\n  colour: red\nparameters:\n  NVKQP: 50\n");
  EXPECT_EQ(e.where(), "test.yaml:4");
  EXPECT_EQ(e.key(), "colour");
}

TEST(ProfileLoader, RejectsMetadataWithoutUnits) {
  auto e = load_error("name: x\nmotor:\n  phase_inductance: 6.2\nparameters:\n  NVKQP: 50\n");
  EXPECT_EQ(e.rule(), "unit");
  EXPECT_EQ(e.where(), "test.yaml:3");
  EXPECT_EQ(e.key(), "phase_inductance");
  EXPECT_EQ(load_error("name: x\nmotor:\n  continuous_current: 3 V\nparameters:\n  NVKQP: 50\n").rule(),
            "unit");
  EXPECT_EQ(load_error("name: x\nmotor:\n  phase_resistance: -1 ohm\nparameters:\n  NVKQP: 50\n").rule(),
            "unit");
  EXPECT_EQ(load_error("name: x\nsupply:\n  bus_voltage: 48\nparameters:\n  NVKQP: 50\n").rule(), "unit");
  // A peak below the continuous rating is a typo.
  e = load_error(
      "name: x\nmotor:\n  continuous_current: 3 A\n  peak_current: 2 A\nparameters:\n  NVKQP: 50\n");
  EXPECT_EQ(e.rule(), "motor");
  EXPECT_EQ(e.where(), "test.yaml:4");
}

TEST(ProfileLoader, RejectsInvalidYamlWithLine) {
  const auto e = load_error("name: x\nparameters:\n  NVKQP: [50\n");
  EXPECT_EQ(e.rule(), "yaml");
  EXPECT_EQ(std::string(e.what()).rfind("test.yaml:", 0), 0u) << e.what();
}

TEST(ProfileLoader, ReportsMissingFile) {
  try {
    load_profile_file("/nonexistent/profile.yaml", db());
    FAIL() << "expected a ProfileError";
  } catch (const ProfileError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/profile.yaml"), std::string::npos);
  }
}

TEST(ProfileLoader, FileErrorsNameTheFile) {
  const auto path = std::filesystem::temp_directory_path() / "i20-profile-loader-test.yaml";
  std::ofstream(path) << "name: x\nparameters:\n  NVKQP: 50\n  NVMAXCURRENT: 750\n";
  try {
    load_profile_file(path, db());
    FAIL() << "expected a ProfileError";
  } catch (const ProfileError& e) {
    EXPECT_EQ(e.where(), path.string() + ":4");
    EXPECT_EQ(e.rule(), "unit-required");
  }
  std::filesystem::remove(path);
}

// Fuzz findings (fuzz/regressions/profile_loader): "nan A" became NaN converted to an
// int64; "1e-20 A" rounded to 0 A. Both are value errors at their line.
TEST(ProfileLoader, RejectsValuesThatAreNotExactNumbers) {
  for (const char* value : {"nan A", "NaN A", "inf A", "-inf A", "1e-20 A", "0x1p3 A", "--10 A", "7,5 A"}) {
    const auto e = load_error(with_params(std::string("  NVMAXCURRENT: ") + value + "\n"));
    EXPECT_EQ(e.rule(), "value") << value << ": " << e.what();
    EXPECT_EQ(e.where(), "test.yaml:3") << value;
  }
  EXPECT_EQ(load_error(with_params("  NVMAXCURRENT: {raw: --1000}\n")).rule(), "value");
  EXPECT_EQ(load_error(with_params("  NVMAXCURRENT: {raw: 18446744073709551616}\n")).reason(),
            "18446744073709551616 is out of range for NVMAXCURRENT: 0.00 A .. 30.00 A (raw 0..3000)");
}

TEST(ProfileLoader, RejectsQuantitiesThatAreNotPlainPositiveNumbers) {
  for (const char* q : {"nan ohm", "inf ohm", "0x1p3 ohm", "1e300 ohm", "1e-300 ohm", "--2 ohm", "0 ohm"}) {
    const auto e =
        load_error(std::string("name: x\nmotor:\n  phase_resistance: ") + q + "\nparameters:\n  NVKQP: 50\n");
    EXPECT_EQ(e.rule(), "unit") << q << ": " << e.what();
    EXPECT_EQ(e.where(), "test.yaml:3") << q;
  }
  EXPECT_NE(load_error("name: x\nmotor:\n  phase_resistance: 1,9 ohm\nparameters:\n  NVKQP: 50\n")
                .reason()
                .find("decimal comma"),
            std::string::npos);
  EXPECT_NE(load_error("name: x\nmotor:\n  phase_resistance: 1e300 ohm\nparameters:\n  NVKQP: 50\n")
                .reason()
                .find("out of range"),
            std::string::npos);
}

// A profile is a few KB; a wrong file is refused before anything reads it into memory.
TEST(ProfileLoader, RefusesHugeFilesAndDirectoriesBeforeParsing) {
  const auto dir = std::filesystem::temp_directory_path() / "i20-profile-loader-bounds";
  std::filesystem::create_directories(dir);
  const auto huge = dir / "huge.yaml";
  std::ofstream(huge) << "";
  std::filesystem::resize_file(huge, 126u << 20);  // sparse: nothing on disk
  try {
    load_profile_file(huge, db());
    FAIL() << "a 126 MB profile was accepted";
  } catch (const ProfileError& e) {
    EXPECT_EQ(std::string(e.what()),
              huge.string() +
                  ": the profile is larger than 1048576 bytes, the limit for it (a real one "
                  "is a few KB) [file]");
  }
  try {
    load_profile_file(dir, db());
    FAIL() << "a directory was accepted";
  } catch (const ProfileError& e) {
    EXPECT_EQ(std::string(e.what()), dir.string() + ": is a directory, not a profile [file]");
  }
  std::filesystem::remove_all(dir);
}

TEST(ProfileLoader, DeepNestingIsOneLineOfError) {
  const auto e = load_error("name: x\nparameters: " + std::string(5000, '[') + std::string(5000, ']') + "\n");
  EXPECT_EQ(e.rule(), "yaml");
  EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
}

TEST(ProfileWriter, RoundTripsThroughTheLoader) {
  Profile p = load(R"(name: "tricky \"name\": with colon"
description: one line
motor:
  make: Acme
  continuous_current: 2.7 A
  phase_inductance: 6.2 mH
  phase_resistance: 1.9 ohm
supply:
  description: "bench: 48 V"
  bus_voltage: 48 V
notes: |
  line one
    indented line two
target: nv
parameters:
  NVMAXCURRENT: 7.5 A
  NVBRAKEONV: 75 V
  NVKQP: {value: 60, target: both}
  BUSUNDERV: {value: 24 V, target: working}
)");
  p.comments = {"Saved from a card", "on a date"};
  const std::string yaml = to_yaml(p, db());
  EXPECT_EQ(yaml.rfind("# Saved from a card\n# on a date\n", 0), 0u) << yaml;
  EXPECT_NE(yaml.find("NVMAXCURRENT: 7.50 A"), std::string::npos) << yaml;
  const Profile q = load(yaml);
  EXPECT_EQ(q.name, p.name);
  EXPECT_EQ(q.description, p.description);
  EXPECT_EQ(q.notes, p.notes);
  EXPECT_EQ(q.supply.description, p.supply.description);
  EXPECT_EQ(q.supply.bus_voltage_v, p.supply.bus_voltage_v);
  EXPECT_EQ(q.motor.make, p.motor.make);
  EXPECT_NEAR(*q.motor.phase_inductance_h, *p.motor.phase_inductance_h, 1e-12);
  EXPECT_EQ(q.target, p.target);
  ASSERT_EQ(q.settings.size(), p.settings.size());
  for (std::size_t i = 0; i < q.settings.size(); ++i) {
    EXPECT_EQ(q.settings[i].name, p.settings[i].name);
    EXPECT_EQ(q.settings[i].raw, p.settings[i].raw);
    EXPECT_EQ(q.settings[i].target, p.settings[i].target);
  }
}

TEST(ProfileWriter, FallsBackToRawWhenEngineeringTextWouldNotReadBack) {
  // ANGLE's scale (360/65536 deg) has more decimals than the formatter prints.
  Profile p;
  p.name = "angle";
  p.settings = {{"ANGLE", 1, std::nullopt, 0}};
  const std::string yaml = to_yaml(p, db());
  EXPECT_NE(yaml.find("ANGLE: {raw: 1}"), std::string::npos) << yaml;
  EXPECT_EQ(load(yaml).settings[0].raw, 1);
}
