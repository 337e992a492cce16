// SPDX-License-Identifier: GPL-2.0-or-later
// The bad-input table: arguments, environment and files a user can get wrong, each run as a
// process against `i20sim --pty`. Every case asserts the exact one-line error, the exit code
// (2 bad input, 3 refused by a safety rule, 1 card not reached), and that nothing was
// written: no write command in the simulator's trace and the EEPROM image byte for byte.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "harness.hpp"

using namespace i20::test;

namespace {

struct BadInput {
  std::string name;
  std::string program;  // i20, wpd, rpd or i20sim
  std::vector<std::string> args;
  std::map<std::string, std::string> env;  // on top of COMPORT={PORT}, BAUDRATE, PROTOCOL
  int exit_code;
  std::string error;          // the whole of stderr: one line
  bool sends_nothing = true;  // bad input is caught before the first byte goes out
  friend void PrintTo(const BadInput& c, std::ostream* os) { *os << c.name; }
};

// Placeholders in args, env and the expected error: the simulator's port, the files' folder.
std::string expand(std::string text, const std::string& port, const std::string& dir) {
  for (const auto& [key, value] : {std::pair{std::string("{PORT}"), port}, {std::string("{DIR}"), dir}})
    for (auto at = text.find(key); at != std::string::npos; at = text.find(key, at + value.size()))
      text.replace(at, key.size(), value);
  return text;
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// The files the file cases point at, in a fresh folder.
void write_bad_files(const TempDir& dir) {
  std::filesystem::create_directory(dir / "folder");
  std::string binary = "name: x\n";
  for (int i = 0; i < 256; ++i) binary += static_cast<char>(i);
  write_file(dir / "binary.yaml", binary);
  write_file(dir / "huge.yaml", std::string(2 << 20, '#'));  // 2 MiB: over the 1 MiB bound
  write_file(dir / "deep.yaml", "a: " + std::string(5000, '[') + std::string(5000, ']') + "\n");
  const std::string head = "name: bad\nparameters:\n";
  write_file(dir / "comma.yaml", head + "  NVMAXCURRENT: 12,5 A\n");
  write_file(dir / "twice.yaml", head + "  NVMAXCURRENT: 12 A\n  NVMAXCURRENT: 13 A\n");
  write_file(dir / "unknown.yaml", head + "  NVFROB: 12\n");
  write_file(dir / "empty.yaml", "");
  write_file(dir / "syntax.yaml", head + "  NVMAXCURRENT: [12 A\n");
  write_file(dir / "rating.yaml", head + "  NVMAXCURRENT: 45 A\n");
  write_file(dir / "unitless.yaml", head + "  NVMAXCURRENT: 12\n");
  write_file(dir / "overlay-comma.yaml", "parameters:\n  - name: NVMAXCURRENT\n    max: 2,5\n");
}

const std::string kCli = " (`i20 --help` explains the options)";
const std::string kPortNotFound =
    " does not exist: is the USB serial adapter (e.g. 3I22) plugged in? List the serial ports to find the "
    "right one";
const std::string kBaudHint = ", not a baud rate: setup mode needs BAUDRATE=115200";

std::vector<BadInput> table() {
  const std::vector<std::string> i20 = {"--port", "{PORT}"};
  auto with = [](std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  return {
      // Values on the command line.
      {"SetTwoMinusSigns",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=--1000"}),
       {},
       2,
       "i20: error: NVMAXCURRENT=--1000: not a number (e.g. 30.00 A)"},
      {"SetHexWithInnerSign",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=-0x-3E8"}),
       {},
       2,
       "i20: error: NVMAXCURRENT=-0x-3E8: not an integer (hexadecimal is 0x and the digits 0-9, A-F, "
       "after at most one sign)"},
      {"SetNan",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=nanA"}),
       {},
       2,
       "i20: error: NVMAXCURRENT=nanA: not a number (e.g. 30.00 A)"},
      {"SetFinerThanResolution",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=1e-20A"}),
       {},
       2,
       "i20: error: NVMAXCURRENT=1e-20A: finer than its resolution of 0.01 A"},
      {"SetDecimalComma",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=12,5A"}),
       {},
       2,
       "i20: error: NVMAXCURRENT=12,5A: decimal comma: write the fraction with a point"},
      {"SetWrongUnit",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=12V"}),
       {},
       2,
       "i20: error: NVMAXCURRENT=12V: a current is in A or mA, not V"},
      {"SetBareNumberForAUnit",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=15", "--dry-run"}),
       {},
       2,
       "i20: error: NVMAXCURRENT=15: a current needs its unit (15A, 15mA) or raw:15 for card counts (10 mA "
       "each)"},
      {"SetUnitInTheWrongCase",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=7.5a"}),
       {},
       2,
       "i20: error: NVMAXCURRENT=7.5a: unit 'a' is not known; did you mean 'A'?"},
      {"SetUnknownParameter",
       "i20",
       with(i20, {"set", "NOSUCH=1"}),
       {},
       2,
       "i20: error: unknown parameter 'NOSUCH' (list them all with `i20 dump` or see params/8i20.yaml)"},
      {"SetWithoutEquals",
       "i20",
       with(i20, {"set", "NVMAXCURRENT"}),
       {},
       2,
       "i20: error: 'NVMAXCURRENT' is not NAME=VALUE (e.g. NVBRAKEONV=320V or NVMAXCURRENT=raw:750)"},
      {"SetSameNameTwice",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=12A", "NVMAXCURRENT=13A"}),
       {},
       2,
       "i20: error: NVMAXCURRENT is given twice on the command line"},
      {"SetNothing", "i20", with(i20, {"set"}), {}, 2, "i20: error: ASSIGNMENT is required" + kCli},
      {"SetAboveTheCardsRating",
       "i20",
       with(i20, {"set", "NVMAXCURRENT=45A"}),
       {},
       3,
       "i20: refused: NVMAXCURRENT = 45.00 A (raw 4500) is outside its valid range 0.00 A .. 30.00 A (raw "
       "0..3000); "
       "nothing was written"},
      {"SetReadOnly",
       "i20",
       with(i20, {"set", "FAULT=0"}),
       {},
       3,
       "i20: refused: FAULT is read-only: faults clear through CLEARFAULT (i20 clear-faults)"},
      {"SetBrakeOffAboveBrakeOn",
       "i20",
       with(i20, {"set", "NVBRAKEOFFV=370V"}),
       {},
       3,
       "i20: refused: NVBRAKEOFFV: NVBRAKEOFFV 370.00 V (profile) must be below NVBRAKEONV 360.00 V (card): "
       "the "
       "manual requires BrakeOn always higher than BrakeOff [brake-order]; nothing was written",
       false},
      {"GetUnknownParameter",
       "i20",
       with(i20, {"get", "NOSUCH"}),
       {},
       2,
       "i20: error: unknown parameter 'NOSUCH' (list them all with `i20 dump` or see params/8i20.yaml)"},
      {"GetNothing", "i20", with(i20, {"get"}), {}, 2, "i20: error: NAME is required" + kCli},
      {"MaskWithoutOnOrOff",
       "i20",
       with(i20, {"faults", "mask", "frob"}),
       {},
       2,
       "i20: error: say on or off: `i20 faults mask frob on` masks it, `... off` unmasks it"},
      // Options and commands.
      {"UnknownCommand",
       "i20",
       with(i20, {"frobnicate"}),
       {},
       2,
       "i20: error: unknown command 'frobnicate'; `i20 --help` lists them"},
      {"MisspelledCommand",
       "i20",
       with(i20, {"inof"}),
       {},
       2,
       "i20: error: unknown command 'inof': did you mean info?"},
      {"UnknownOption",
       "i20",
       with(i20, {"get", "BUSV", "--frob"}),
       {},
       2,
       "i20: error: The following argument was not expected: --frob" + kCli},
      {"BaudOutOfRange",
       "i20",
       with(i20, {"--baud", "0", "get", "BUSV"}),
       {},
       2,
       "i20: error: --baud: Value 0 not in range 1200 to 12000000" + kCli},
      {"TimeoutOutOfRange",
       "i20",
       with(i20, {"--timeout", "-5", "get", "BUSV"}),
       {},
       2,
       "i20: error: --timeout: Value -5 not in range 1 to 10000" + kCli},
      {"TwoTargets",
       "i20",
       with(i20, {"--sim", "get", "BUSV"}),
       {},
       2,
       "i20: error: Requires at most 1 options be given from [-p,--port,--sim,--eth]" + kCli},
      {"ChannelWithoutEthernet",
       "i20",
       with(i20, {"--channel", "3", "get", "BUSV"}),
       {},
       2,
       "i20: error: --channel requires --eth" + kCli},
      {"EthernetAddressNotIpv4",
       "i20",
       {"--eth", "999.1.1.1", "get", "BUSV"},
       {},
       2,
       "i20: error: '999.1.1.1' is not an IPv4 address (expected e.g. 192.168.1.121)"},
      {"EthernetPortOutOfRange",
       "i20",
       {"--eth", "127.0.0.1:99999", "get", "BUSV"},
       {},
       2,
       "i20: error: '99999' is not a UDP port (1..65535)"},
      {"EthernetUrlChannelOutOfRange",
       "i20",
       {"--port", "eth://127.0.0.1/ch9", "get", "BUSV"},
       {},
       2,
       "i20: error: channel 9 is out of range (0..7)"},
      {"SerialPortMissing",
       "i20",
       {"--port", "{DIR}/ttyUSB7", "get", "BUSV"},
       {},
       1,
       "i20: error: {DIR}/ttyUSB7" + kPortNotFound},
      // wpd and rpd.
      {"WpdValueOverflows",
       "wpd",
       {"NVMAXCURRENT", "99999999999999999999"},
       {},
       2,
       "wpd: error: 99999999999999999999 is out of range for NVMAXCURRENT: 0.00 A .. 30.00 A (raw 0..3000)"},
      {"WpdFraction",
       "wpd",
       {"NVMAXCURRENT", "12.5"},
       {},
       2,
       "wpd: error: NVMAXCURRENT: '12.5' is not an integer (raw values are decimal or 0x hexadecimal)"},
      {"WpdDecimalComma",
       "wpd",
       {"NVMAXCURRENT", "12,5"},
       {},
       2,
       "wpd: error: NVMAXCURRENT: '12,5' is not an integer (raw values are decimal or 0x hexadecimal)"},
      {"WpdEmptyValue",
       "wpd",
       {"NVMAXCURRENT", ""},
       {},
       2,
       "wpd: error: NVMAXCURRENT: '' is not an integer (raw values are decimal or 0x hexadecimal)"},
      {"WpdBareHexPrefix",
       "wpd",
       {"NVMAXCURRENT", "0x"},
       {},
       2,
       "wpd: error: NVMAXCURRENT: '0x' is not an integer (raw values are decimal or 0x hexadecimal)"},
      {"WpdUnknownParameter",
       "wpd",
       {"NOSUCH", "1"},
       {},
       2,
       "wpd: error: unknown parameter 'NOSUCH' (list them all with `i20 dump` or see params/8i20.yaml)"},
      {"WpdMissingValue",
       "wpd",
       {"NVMAXCURRENT"},
       {},
       2,
       "wpd: error: VALUE is required (`wpd --help` explains the options)"},
      {"WpdBrakeOnBelowBrakeOff",
       "wpd",
       {"NVBRAKEONV", "30000"},
       {},
       3,
       "wpd: refused: NVBRAKEONV: NVBRAKEOFFV 340.00 V (card) must be below NVBRAKEONV 300.00 V (profile): "
       "the "
       "manual requires BrakeOn always higher than BrakeOff [brake-order] (and 1 more: NVBRAKEONV "
       "[bus-measured-brake]); nothing was written",
       false},
      {"RpdUnknownFormat",
       "rpd",
       {"NVMAXCURRENT", "X"},
       {},
       2,
       "rpd: error: H: X not in {H,h} (`rpd --help` explains the options)"},
      {"RpdExtraArgument",
       "rpd",
       {"NVMAXCURRENT", "H", "extra"},
       {},
       2,
       "rpd: error: The following argument was not expected: extra (`rpd --help` explains the options)"},
      // The environment the legacy tools (and i20) read.
      {"ComportUnset",
       "wpd",
       {"NVMAXCURRENT", "1200"},
       {{"COMPORT", ""}},
       2,
       "wpd: error: no port: set COMPORT (e.g. export COMPORT=/dev/ttyUSB0; `i20 ports` lists them) or pass "
       "--port, or --sim to try the built-in simulator"},
      {"ComportMissingDevice",
       "rpd",
       {"NVMAXCURRENT"},
       {{"COMPORT", "{DIR}/ttyUSB7"}},
       1,
       "rpd: error: {DIR}/ttyUSB7" + kPortNotFound},
      {"BaudrateZero",
       "wpd",
       {"NVMAXCURRENT", "1200"},
       {{"BAUDRATE", "0"}},
       2,
       "wpd: error: BAUDRATE is '0'" + kBaudHint},
      {"BaudrateNegative",
       "wpd",
       {"NVMAXCURRENT", "1200"},
       {{"BAUDRATE", "-5"}},
       2,
       "wpd: error: BAUDRATE is '-5'" + kBaudHint},
      {"BaudrateNotANumber",
       "rpd",
       {"NVMAXCURRENT"},
       {{"BAUDRATE", "fast"}},
       2,
       "rpd: error: BAUDRATE is 'fast'" + kBaudHint},
      {"BaudrateZeroForI20",
       "i20",
       {"get", "BUSV"},
       {{"BAUDRATE", "0"}},
       2,
       "i20: error: BAUDRATE is '0'" + kBaudHint},
      {"ProtocolNotLbp",
       "wpd",
       {"NVMAXCURRENT", "1200"},
       {{"PROTOCOL", "SPI"}},
       2,
       "wpd: error: PROTOCOL is 'SPI' but the 8I20 speaks LBP: set PROTOCOL=LBP"},
      {"ParamsVariableMissingFile",
       "i20",
       with(i20, {"get", "BUSV"}),
       {{"I20_PARAMS", "{DIR}/none.yaml"}},
       2,
       "i20: error: {DIR}/none.yaml: cannot open the parameter file (does it exist and is it readable?)"},
      {"ParamsVariableIsAFolder",
       "i20",
       with(i20, {"get", "BUSV"}),
       {{"I20_PARAMS", "{DIR}/folder"}},
       2,
       "i20: error: {DIR}/folder: is a directory, not a parameter file"},
      // Parameter overlay files.
      {"OverlayIsAFolder",
       "i20",
       with(i20, {"--params", "{DIR}/folder", "get", "BUSV"}),
       {},
       2,
       "i20: error: --params: File is actually a directory: {DIR}/folder" + kCli},
      {"OverlayIsBinary",
       "i20",
       with(i20, {"--params", "{DIR}/binary.yaml", "get", "BUSV"}),
       {},
       2,
       "i20: error: {DIR}/binary.yaml: the parameter file holds the control byte 0x00 at offset 8: it is not "
       "a "
       "YAML text file"},
      {"OverlayIsHuge",
       "i20",
       with(i20, {"--params", "{DIR}/huge.yaml", "get", "BUSV"}),
       {},
       2,
       "i20: error: {DIR}/huge.yaml: the parameter file is larger than 1048576 bytes, the limit for it (a "
       "real "
       "one is a few KB)"},
      {"OverlayNestsTooDeep",
       "i20",
       with(i20, {"--params", "{DIR}/deep.yaml", "get", "BUSV"}),
       {},
       2,
       "i20: error: {DIR}/deep.yaml:1: not valid YAML: nested 500 levels deep, more than the parser takes (a "
       "real file nests a few levels)"},
      {"OverlayDecimalComma",
       "i20",
       with(i20, {"--params", "{DIR}/overlay-comma.yaml", "get", "BUSV"}),
       {},
       2,
       "i20: error: {DIR}/overlay-comma.yaml:3: 'max' must be an integer, not '2,5'"},
      // Profile files.
      {"ProfileIsAFolder",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/folder", "--yes"}),
       {},
       2,
       "{DIR}/folder: error: is a directory, not a profile [file]"},
      {"ProfileIsBinary",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/binary.yaml", "--yes"}),
       {},
       2,
       "{DIR}/binary.yaml: error: the profile holds the control byte 0x00 at offset 8: it is not a YAML text "
       "file [file]"},
      {"ProfileIsHuge",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/huge.yaml", "--yes"}),
       {},
       2,
       "{DIR}/huge.yaml: error: the profile is larger than 1048576 bytes, the limit for it (a real one is a "
       "few "
       "KB) [file]"},
      {"ProfileNestsTooDeep",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/deep.yaml", "--yes"}),
       {},
       2,
       "{DIR}/deep.yaml:1: error: not valid YAML: nested 500 levels deep, more than the parser takes (a real "
       "file nests a few levels) [yaml]"},
      {"ProfileDecimalComma",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/comma.yaml", "--yes"}),
       {},
       2,
       "{DIR}/comma.yaml:3: error: NVMAXCURRENT: '12,5 A': decimal comma: write the fraction with a "
       "point "
       "[value]"},
      {"ProfileNameTwice",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/twice.yaml", "--yes"}),
       {},
       2,
       "{DIR}/twice.yaml:4: error: NVMAXCURRENT: given twice [duplicate]"},
      {"ProfileUnknownParameter",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/unknown.yaml", "--yes"}),
       {},
       2,
       "{DIR}/unknown.yaml:3: error: NVFROB: unknown parameter 'NVFROB' (list them all with `i20 dump` or "
       "see "
       "params/8i20.yaml) [unknown-parameter]"},
      {"ProfileEmpty",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/empty.yaml", "--yes"}),
       {},
       2,
       "{DIR}/empty.yaml:1: error: a profile is a map with name and parameters [schema]"},
      {"ProfileSyntaxError",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/syntax.yaml", "--yes"}),
       {},
       2,
       "{DIR}/syntax.yaml:4: error: not valid YAML: end of sequence flow not found [yaml]"},
      {"ProfileWithoutUnit",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/unitless.yaml", "--yes"}),
       {},
       2,
       "{DIR}/unitless.yaml:3: error: NVMAXCURRENT: a current needs its unit (12A, 12mA) or raw:12 for card "
       "counts (10 mA each) [unit-required]"},
      {"ProfileAboveTheCardsRating",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/rating.yaml", "--yes"}),
       {},
       3,
       "i20: refused: NVMAXCURRENT = 45.00 A (raw 4500) is outside its valid range 0.00 A .. 30.00 A (raw "
       "0..3000); "
       "nothing was written"},
      {"ProfileNotFound",
       "i20",
       with(i20, {"profile", "apply", "{DIR}/none.yaml", "--yes"}),
       {},
       2,
       "i20: error: FILE: profile file '{DIR}/none.yaml' does not exist" + kCli},
      // The simulator answers bad arguments as the tools do: one line, exit 2.
      {"SimulatorUnknownOption",
       "i20sim",
       {"--pty", "--frob"},
       {},
       2,
       "i20sim: error: The following argument was not expected: --frob (`i20sim --help` explains the "
       "options)"},
      {"SimulatorBadNumber",
       "i20sim",
       {"--pty", "--reset-ms", "soon"},
       {},
       2,
       "i20sim: error: Could not convert: --reset-ms = soon (`i20sim --help` explains the options)"},
      {"SimulatorNothingToServe",
       "i20sim",
       {},
       {},
       2,
       "i20sim: error: nothing to do: give --pty or --eth ADDR to serve (or --print-map) (`i20sim --help` "
       "explains the options)"},
  };
}

class BadInputTable : public ::testing::TestWithParam<BadInput> {
 protected:
  BadInputTable() : sim_({"--eeprom", (dir_ / "card.eeprom").string()}) { write_bad_files(dir_); }

  TempDir dir_;
  SimProcess sim_;
};

TEST_P(BadInputTable, OneLineErrorExitCodeAndNothingWritten) {
  const BadInput& c = GetParam();
  const std::string dir = dir_.path().string();
  std::map<std::string, std::string> env{{"COMPORT", sim_.port()},
                                         {"BAUDRATE", "115200"},
                                         {"PROTOCOL", "LBP"},
                                         {"I20_PARAMS", ""},
                                         {"XDG_CONFIG_HOME", "/nonexistent"},
                                         {"XDG_STATE_HOME", dir}};
  for (const auto& [key, value] : c.env) env[key] = expand(value, sim_.port(), dir);
  std::vector<std::string> args;
  for (const auto& a : c.args) args.push_back(expand(a, sim_.port(), dir));

  const std::string eeprom_before = read_file(dir_ / "card.eeprom");
  const std::size_t commands_before = sim_.commands_seen();
  const Result r = run(c.program, args, env);

  EXPECT_EQ(r.exit_code, c.exit_code) << r.out << r.err;
  EXPECT_EQ(r.err, expand(c.error, sim_.port(), dir) + "\n");
  EXPECT_EQ(sim_.writes_seen(), 0u) << sim_.trace();
  EXPECT_EQ(read_file(dir_ / "card.eeprom"), eeprom_before) << "the EEPROM image changed";
  if (c.sends_nothing) {
    EXPECT_EQ(sim_.commands_seen(), commands_before) << "bad input reached the card";
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, BadInputTable, ::testing::ValuesIn(table()),
                         [](const auto& info) { return info.param.name; });

}  // namespace
