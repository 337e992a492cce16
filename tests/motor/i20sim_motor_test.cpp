// SPDX-License-Identifier: GPL-2.0-or-later
// `i20sim --motor FILE.yaml` as a process: the shipped motors load, the control lines reach
// the motor, and a bad file ends the start with one line naming file, line and key.
#include <gtest/gtest.h>

#include <fstream>

#include "harness.hpp"

namespace {

using namespace i20::test;

std::string shipped(const std::string& name) {
  return (source_dir() / "motors" / name).string();
}

TEST(I20simMotor, TheShippedMotorIsDrivenAndShown) {
  SimProcess sim({"--operate", "--motor", shipped("servo-halls-index.yaml")});
  const std::string state = sim.control("motor");
  for (const char* field : {"motor_angle=", "speed=", "electrical=", "encoder=0", "halls=001", "iu=", "iq="})
    EXPECT_NE(state.find(field), std::string::npos) << field << " in " << state;
  EXPECT_EQ(sim.control("motor load 0.3Nm"), "ok");
  EXPECT_NE(sim.control("motor").find("load=0.3Nm"), std::string::npos);
  EXPECT_EQ(sim.control("motor load 3").rfind("error: load: 3: a torque needs its unit", 0), 0u);
  EXPECT_NE(sim.control("show").find("motor_angle="), std::string::npos);
}

// The shipped vertical axis: its head hangs on the coupling, and the `motor` line shows where
// the load and the machine are; a machine key changes live like any other.
TEST(I20simMotor, TheShippedVerticalAxisShowsItsLoadAndPosition) {
  SimProcess sim({"--operate", "--motor", shipped("vertical-screw-axis.yaml")});
  const std::string state = sim.control("motor");
  for (const char* field : {"load=0.312Nm", "load_angle=", "load_speed=", "position="})
    EXPECT_NE(state.find(field), std::string::npos) << field << " in " << state;
  // Cross-key rules hold live too: a damping without a stiffness is refused, and the motor
  // is left as it was.
  EXPECT_EQ(sim.control("motor machine.stiffness 0Nm/rad")
                .rfind("error: machine.damping belongs to a compliant coupling", 0),
            0u);
  EXPECT_EQ(sim.control("motor machine.damping 0Nm/(rad/s)"), "ok");
  EXPECT_EQ(sim.control("motor machine.stiffness 0Nm/rad"), "ok");
  EXPECT_EQ(sim.control("motor machine.lead 5").rfind("error: machine.lead: 5: a length needs its unit", 0),
            0u);
}

TEST(I20simMotor, ABadMotorFileIsOneLineAndExitCode2) {
  TempDir dir;
  const auto path = dir / "bad.yaml";
  std::ofstream(path) << "pole_pairs: 4\nresistance: 0.6ohm\ninductance: 1.75mH\ntorque_constant: 0.2Nm/A\n"
                         "inertia: -0.1kgcm^2\n";
  const auto r = run("i20sim", {"--pty", "--motor", path.string()}, {}, 10);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "i20sim: " + path.string() + ":5: inertia: -0.1kgcm^2: must be positive\n");
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(I20simMotor, OneMotorPerChannelAndOnlyWhereThereIsAnEightI20) {
  const auto small = shipped("small-servo.yaml");
  auto r = run("i20sim", {"--pty", "--motor", small, "--motor", small}, {}, 10);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("one motor; several axes need --eth"), std::string::npos) << r.err;
  r = run("i20sim", {"--eth", "127.0.0.1:0", "--motor", small, "--motor", small}, {}, 10);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("channel 0 already has a motor"), std::string::npos) << r.err;
  r = run("i20sim", {"--eth", "127.0.0.1:0", "--no-stdin", "--motor", shipped("servo-halls-index.yaml")}, {},
          10);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("sits on channel 1, which has no 8I20"), std::string::npos) << r.err;
}

}  // namespace
