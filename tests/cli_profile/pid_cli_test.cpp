// SPDX-License-Identifier: GPL-2.0-or-later
// i20 pid as a process: gains from a motor file's machine or from measured values (the same
// axis gives the same gains either way), the [JOINT_n] lines i20 hal's file reads, -o written
// whole and never over an existing file without --overwrite, and every bad value refused with
// one line, exit 2, nothing written.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "cli_profile_util.hpp"

using namespace i20::test;

namespace {

std::string motor_file(const std::string& name) {
  return (source_dir() / "motors" / name).string();
}

Result pid(std::vector<std::string> args) {
  args.insert(args.begin(), "pid");
  return run("i20", args);
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string line_of(const std::string& text, const std::string& key) {
  const auto at = text.find("\n" + key + " = ");
  return at == std::string::npos ? "" : text.substr(at + 1, text.find('\n', at + 1) - at - 1);
}

}  // namespace

TEST(PidCli, AMotorFilesMachineGivesTheJointsGains) {
  const auto r =
      pid({"--motor", motor_file("vertical-screw-axis.yaml"), "--max-current", "10A", "--joint", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("[JOINT_1]\n", 0), 0u) << r.out;
  for (const char* key : {"P", "I", "D", "FF0", "FF1", "FF2", "BIAS", "DEADBAND"})
    EXPECT_FALSE(line_of(r.out, key).empty()) << key << " in " << r.out;
  // The head's weight, 0.312 Nm, over 0.45 Nm/A; FF2 = J / (Kt r) in amps per mm/s^2.
  EXPECT_EQ(line_of(r.out, "BIAS"), "BIAS = 0.693333");
  EXPECT_NE(r.out.find("phase margin"), std::string::npos);
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(PidCli, MeasuredValuesGiveWhatTheSameMotorFileGives) {
  // vertical-screw-axis.yaml made rigid (no coupling): 0.6 + 0.2 kgcm^2 + 40 kg x (5 mm / 2 pi)^2
  // = 1.0533030 kgcm^2.
  TempDir dir;
  const auto rigid = dir / "rigid.yaml";
  {
    std::ifstream in(motor_file("vertical-screw-axis.yaml"));
    std::ofstream out(rigid);
    for (std::string line; std::getline(in, line);)
      if (line.find("stiffness:") == std::string::npos && line.find("damping:") == std::string::npos)
        out << line << "\n";
  }
  const auto from_file = pid({"--motor", rigid.string(), "--max-current", "10A"});
  ASSERT_EQ(from_file.exit_code, 0) << from_file.err;
  const auto from_flags =
      pid({"--inertia", "1.0533030kgcm^2", "--viscous", "0.05mNm/(rad/s)", "--coulomb", "0.02Nm", "--bias",
           "0.312Nm", "--torque-constant", "0.45Nm/A", "--lead", "5mm", "--max-current", "10A"});
  ASSERT_EQ(from_flags.exit_code, 0) << from_flags.err;
  for (const char* key : {"P", "I", "D", "FF1", "FF2", "BIAS"})
    EXPECT_EQ(line_of(from_flags.out, key), line_of(from_file.out, key)) << key;
}

// A coupling that rings: designed on the two masses it keeps its margins at the peak too, so
// it crosses over lower than the rigid model would let it.
TEST(PidCli, TheTwoMassesOfAResonanceLowerTheCrossover) {
  const std::vector<std::string> axis{"--inertia",   "1.0533kgcm^2", "--torque-constant", "0.45Nm/A",
                                      "--lead",      "5mm",          "--max-current",     "10A",
                                      "--resonance", "180Hz"};
  auto two = axis;
  for (const char* word : {"--rotor-inertia", "0.6kgcm^2"}) two.push_back(word);
  const auto rigid = pid(axis), masses = pid(two);
  ASSERT_EQ(rigid.exit_code, 0) << rigid.err;
  ASSERT_EQ(masses.exit_code, 0) << masses.err;
  const auto crossover = [](const std::string& out) {
    return std::stod(out.substr(out.find("crossover ") + 10));
  };
  EXPECT_LT(crossover(masses.out), crossover(rigid.out));
  auto heavy_rotor = axis;
  for (const char* word : {"--rotor-inertia", "2kgcm^2"}) heavy_rotor.push_back(word);
  const auto r = pid(heavy_rotor);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("the rotor's inertia must be below the total inertia"), std::string::npos) << r.err;
}

// --notch lets the design put a notch at the resonance: the section then carries its biquad
// coefficients and stderr says the HAL must run it; without --notch there is none.
TEST(PidCli, TheNotchIsAskedForAndThenSaidAndWritten) {
  const std::vector<std::string> axis{"--motor", motor_file("vertical-screw-axis.yaml"), "--max-current",
                                      "10A"};
  auto with = axis;
  with.push_back("--notch");
  const auto plain = pid(axis), notched = pid(with);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(notched.exit_code, 0) << notched.err;
  EXPECT_EQ(plain.out.find("NOTCH"), std::string::npos);
  for (const char* key : {"NOTCH_N0", "NOTCH_N1", "NOTCH_N2", "NOTCH_D1", "NOTCH_D2"})
    EXPECT_FALSE(line_of(notched.out, key).empty()) << key << " in " << notched.out;
  EXPECT_NE(notched.err.find("the HAL must run it (i20 hal --notch)"), std::string::npos) << notched.err;
  const auto crossover = [](const std::string& out) {
    return std::stod(out.substr(out.find("crossover ") + 10));
  };
  EXPECT_GT(crossover(notched.out), crossover(plain.out));
}

TEST(PidCli, OutWritesTheSectionAndNeverReplacesAFileUnasked) {
  TempDir dir;
  const auto path = dir / "joint.ini";
  const std::vector<std::string> args{
      "--motor", motor_file("vertical-screw-axis.yaml"), "--max-current", "10A", "-o", path.string()};
  auto r = pid(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("gains written to " + path.string()), std::string::npos) << r.out;
  const std::string written = read_file(path);
  EXPECT_EQ(written.rfind("[JOINT_0]\n", 0), 0u);
  EXPECT_EQ(written.back(), '\n');
  std::ofstream(path) << "mine\n";
  r = pid(args);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(read_file(path), "mine\n");
  auto again = args;
  again.push_back("--overwrite");
  EXPECT_EQ(pid(again).exit_code, 0);
  EXPECT_EQ(read_file(path), written);
}

TEST(PidCli, BadValuesAreOneLineAndExit2) {
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  const std::string axis = motor_file("vertical-screw-axis.yaml");
  const std::vector<Case> cases{
      {{"--max-current", "10A"}, "give --motor FILE, or --inertia, --torque-constant and --lead"},
      {{"--motor", axis}, "--max-current is needed"},
      {{"--motor", axis, "--max-current", "10"}, "--max-current: "},
      {{"--motor", motor_file("small-servo.yaml"), "--max-current", "10A"},
       "small-servo.yaml: the motor file gives no machine.lead"},
      {{"--inertia", "1kgcm^2", "--torque-constant", "0.45Nm/A", "--lead", "5", "--max-current", "10A"},
       "--lead: 5: a length needs its unit"},
      {{"--motor", axis, "--max-current", "10A", "--units", "furlong"},
       "--units: 'furlong' is not mm, m, in or deg"},
      {{"--motor", axis, "--max-current", "10A", "--units", "deg"}, "a motor file's lead is a length"},
      {{"--motor", axis, "--max-current", "10A", "--bias", "0.5Nm"}, "--motor gives the mechanics"},
      {{"--motor", axis, "--max-current", "10A", "--phase-margin", "95"},
       "the phase margin must be 30 to 80 degrees"},
      {{"--motor", axis, "--max-current", "10A", "--inertia", "1kgcm^2"}, "--motor gives the mechanics"},
      {{"--motor", "/", "--max-current", "10A"}, "is a directory, not a motor file"},
      {{"--inertia", "1kgcm^2", "--torque-constant", "0.45Nm/A", "--lead", "5mm", "--max-current", "10A",
        "--resonance", "180Hz", "--notch"},
       "a notch needs the resonance and the rotor's inertia"},
      {{"--inertia", "1kgcm^2", "--torque-constant", "0.45Nm/A", "--lead", "5mm", "--max-current", "10A",
        "--resonance", "480Hz", "--rotor-inertia", "0.6kgcm^2", "--notch"},
       "below half the servo rate"},
  };
  for (const auto& c : cases) {
    const auto r = pid(c.args);
    SCOPED_TRACE(c.says);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST(PidCli, NoLoopThatKeepsTheMarginsIsExit1) {
  // A rigid model a fifth below a 2 Hz resonance: no crossover is left above 0.5 Hz.
  const auto r = pid({"--inertia", "1kgcm^2", "--torque-constant", "0.45Nm/A", "--lead", "5mm",
                      "--max-current", "10A", "--resonance", "2Hz"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no crossover keeps 45 degrees and 8 dB"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// --svg and --csv: the designed gains at work on the motor file's model, drawn and listed.
TEST(PidCli, TheSimulatedMoveIsDrawnAndListed) {
  TempDir dir;
  const auto svg = dir / "move.svg", csv = dir / "move.csv";
  const auto r = pid({"--motor", motor_file("vertical-screw-axis.yaml"), "--max-current", "10A", "--svg",
                      svg.string(), "--csv", csv.string(), "--move-distance", "4", "--move-speed", "10"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("[JOINT_0]\n", 0), 0u) << "the gains still go to stdout";
  // The move runs with the vertical axis's holding brake released (the file has it engaged,
  // as a machine's is while the amplifier is off): held, the peak was 1.3 mm.
  std::smatch peak;
  ASSERT_TRUE(std::regex_search(r.err, peak, std::regex("following error peak ([0-9.e-]+) mm"))) << r.err;
  EXPECT_LT(std::stod(peak[1]), 0.1) << r.err;
  const std::string drawing = read_file(svg);
  for (const char* strip : {"Position (mm)", "Following error (um)", "Current (A)", "</svg>"})
    EXPECT_NE(drawing.find(strip), std::string::npos) << strip;
  const std::string rows = read_file(csv);
  EXPECT_EQ(
      rows.substr(0, rows.find('\n')),
      "time_s,Position: command (mm),Position: encoder (mm),Following error: command - encoder (um),Current: "
      "pid output (A)");
  // 4 mm at 10 mm/s and 500 mm/s^2: 0.42 s a leg and 0.5 s at rest after each, 1 ms a row.
  EXPECT_EQ(std::count(rows.begin(), rows.end(), '\n'), 1 + 1840);
  const auto without = pid({"--inertia", "1kgcm^2", "--torque-constant", "0.45Nm/A", "--lead", "5mm",
                            "--max-current", "10A", "--svg", (dir / "x.svg").string()});
  EXPECT_EQ(without.exit_code, 2);
  EXPECT_NE(without.err.find("--svg and --csv simulate the move on a motor file's model"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.svg"));
}
