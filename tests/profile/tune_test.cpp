// SPDX-License-Identifier: GPL-2.0-or-later
// The tuning calculator: the reference reproduces the manual's defaults, and the gains
// follow the PI current-loop scaling laws (Kp ~ L wc Imax / Vbus, Ki ~ R wc Imax / Vbus).
#include "profile/tune.hpp"

#include <gtest/gtest.h>

#include "profile/error.hpp"
#include "profile/tuning_profile.hpp"
#include "profile/validate.hpp"
#include "profile/writer.hpp"
#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;

namespace {

TuneRequest reference_request() {
  const ReferenceTuning ref;
  TuneRequest r;
  r.motor = ref.motor;
  r.max_current_a = ref.max_current_a;
  r.bus_voltage_v = ref.bus_voltage_v;
  r.bandwidth_hz = ref.bandwidth_hz;
  return r;
}

// A moderate motor whose gains are far from the clamps and the rounding.
TuneRequest typical() {
  TuneRequest r = reference_request();
  r.motor = {1.0, 4e-3};
  r.max_current_a = 10.0;
  r.bus_voltage_v = 300.0;
  r.bandwidth_hz = 400.0;
  return r;
}

}  // namespace

// Manual, CURRENT LOOP TUNING: defaults NVKQP = NVKDP = 50, NVKQI = NVKDI = 150000.
TEST(TuneModel, ReferenceMotorReproducesTheManualDefaults) {
  const auto t = tune(reference_request(), db());
  EXPECT_EQ(t.kp, 50);
  EXPECT_EQ(t.ki, 150000);
  EXPECT_NEAR(t.kp_exact, 50.0, 1e-9);
  EXPECT_NEAR(t.ki_exact, 150000.0, 1e-6);
  EXPECT_TRUE(t.warnings.empty()) << dump(t.warnings);
  EXPECT_EQ(*db().get("NVKQP").default_value, 50);  // the reference is the database's default
  EXPECT_EQ(*db().get("NVKQI").default_value, 150000);
}

TEST(TuneModel, DoublingInductanceDoublesKpOnly) {
  const auto base = tune(typical(), db());
  auto r = typical();
  r.motor.inductance_h *= 2;
  const auto t = tune(r, db());
  EXPECT_NEAR(t.kp_exact, 2 * base.kp_exact, 1e-9 * base.kp_exact);
  EXPECT_NEAR(t.ki_exact, base.ki_exact, 1e-9 * base.ki_exact);
}

TEST(TuneModel, DoublingResistanceDoublesKiOnly) {
  const auto base = tune(typical(), db());
  auto r = typical();
  r.motor.resistance_ohm *= 2;
  const auto t = tune(r, db());
  EXPECT_NEAR(t.kp_exact, base.kp_exact, 1e-9 * base.kp_exact);
  EXPECT_NEAR(t.ki_exact, 2 * base.ki_exact, 1e-9 * base.ki_exact);
}

TEST(TuneModel, BandwidthAndMaxCurrentScaleBothBusVoltageInversely) {
  const auto base = tune(typical(), db());
  auto r = typical();
  r.bandwidth_hz *= 2;
  auto t = tune(r, db());
  EXPECT_NEAR(t.kp_exact, 2 * base.kp_exact, 1e-9 * base.kp_exact);
  EXPECT_NEAR(t.ki_exact, 2 * base.ki_exact, 1e-9 * base.ki_exact);
  r = typical();
  r.max_current_a *= 2;  // commands are fractions of MAXCURRENT: same amps need more counts
  t = tune(r, db());
  EXPECT_NEAR(t.kp_exact, 2 * base.kp_exact, 1e-9 * base.kp_exact);
  EXPECT_NEAR(t.ki_exact, 2 * base.ki_exact, 1e-9 * base.ki_exact);
  r = typical();
  r.bus_voltage_v *= 2;  // outputs are fractions of the bus: same volts need fewer counts
  t = tune(r, db());
  EXPECT_NEAR(t.kp_exact, base.kp_exact / 2, 1e-9 * base.kp_exact);
  EXPECT_NEAR(t.ki_exact, base.ki_exact / 2, 1e-9 * base.ki_exact);
}

TEST(TuneModel, TargetsTheStandardPhysicalGains) {
  const auto r = typical();
  const auto t = tune(r, db());
  const double wc = 2 * 3.141592653589793 * r.bandwidth_hz;
  EXPECT_NEAR(t.target.kp_v_per_a, r.motor.inductance_h * wc, 1e-9);
  EXPECT_NEAR(t.target.ki_v_per_as, r.motor.resistance_ohm * wc, 1e-6);
  // physical_gains() is the inverse of the scaling, up to rounding to counts.
  EXPECT_NEAR(t.achieved.kp_v_per_a, t.target.kp_v_per_a, t.target.kp_v_per_a * 0.5 / t.kp_exact);
  EXPECT_NEAR(t.achieved.ki_v_per_as, t.target.ki_v_per_as, t.target.ki_v_per_as * 0.5 / t.ki_exact);
}

TEST(TuneModel, ClampsToTheParameterRangesWithWarnings) {
  auto r = typical();
  r.motor.inductance_h = 50.0;  // absurd: Kp far beyond 16 bits
  auto t = tune(r, db());
  EXPECT_EQ(t.kp, 65535);
  EXPECT_TRUE(has_rule(t.warnings, "tune-clamp", Severity::Warning));
  r = typical();
  r.motor.inductance_h = 1e-6;  // a tiny Kp would round to zero and switch the P term off
  r.max_current_a = 1.0;
  t = tune(r, db());
  EXPECT_EQ(t.kp, 1);
  EXPECT_TRUE(has_rule(t.warnings, "tune-clamp"));
  r = typical();
  r.motor.inductance_h = 0.5e-3;  // a handful of counts: rounding matters
  r.max_current_a = 3.0;
  t = tune(r, db());
  EXPECT_TRUE(has_rule(t.warnings, "tune-resolution")) << t.kp_exact;
}

TEST(TuneModel, WarnsNearTheLoopRate) {
  auto r = typical();
  r.bandwidth_hz = 600;
  EXPECT_FALSE(has_rule(tune(r, db()).warnings, "tune-bandwidth"));
  r.bandwidth_hz = 900;
  EXPECT_TRUE(has_rule(tune(r, db()).warnings, "tune-bandwidth"));
}

TEST(TuneModel, RejectsNonPhysicalInput) {
  auto r = typical();
  r.motor.inductance_h = 0;
  EXPECT_THROW(tune(r, db()), TuneError);
  r = typical();
  r.bus_voltage_v = -48;
  EXPECT_THROW(tune(r, db()), TuneError);
  r = typical();
  r.max_current_a = 31;
  EXPECT_THROW(tune(r, db()), TuneError);
  r = typical();
  r.bandwidth_hz = 0;
  EXPECT_THROW(tune(r, db()), TuneError);
}

TEST(TuneProfile, RequestComesFromAMotorProfile) {
  const Profile motor = load(with_params("  NVMAXCURRENT: 10 A\n",
                                         "motor:\n  phase_resistance: 1 ohm\n  phase_inductance: 4 mH\n"
                                         "supply:\n  bus_voltage: 300 V\n"));
  const auto r = tune_request_from(motor, db(), 400);
  EXPECT_DOUBLE_EQ(r.motor.resistance_ohm, 1.0);
  EXPECT_NEAR(r.motor.inductance_h, 4e-3, 1e-12);
  EXPECT_DOUBLE_EQ(r.max_current_a, 10.0);
  EXPECT_DOUBLE_EQ(r.bus_voltage_v, 300.0);
  EXPECT_DOUBLE_EQ(r.bandwidth_hz, 400.0);
  EXPECT_THROW(tune_request_from(load(with_params("  NVMAXCURRENT: 10 A\n")), db(), 400), TuneError);
}

TEST(TuneProfile, ResultIsAProfileReadyToValidateAndApply) {
  const auto r = typical();
  const auto t = tune(r, db());
  StepRequest s;
  s.motor = r.motor;
  s.max_current_a = r.max_current_a;
  s.bus_voltage_v = r.bus_voltage_v;
  s.kp = t.kp;
  s.ki = t.ki;
  TuningProfileOptions options;
  options.name = "tuned";
  options.motor.make = "Acme";
  options.motor.continuous_current_a = 4.0;
  options.motor.peak_current_a = 12.0;
  const Profile p = tuning_profile(r, t, simulate_step(s), db(), options);
  const std::string yaml = to_yaml(p, db());
  const Profile loaded = load(yaml);
  const auto findings = validate(loaded, db());
  EXPECT_TRUE(findings.empty()) << dump(findings) << yaml;
  ASSERT_EQ(loaded.settings.size(), 5u);
  EXPECT_EQ(loaded.settings[0].name, "NVMAXCURRENT");
  EXPECT_EQ(loaded.settings[0].raw, 1000);
  EXPECT_EQ(loaded.settings[1].raw, t.kp);
  EXPECT_EQ(loaded.settings[2].raw, t.kp);
  EXPECT_EQ(loaded.settings[3].raw, t.ki);
  EXPECT_EQ(loaded.settings[4].raw, t.ki);
  EXPECT_NEAR(*loaded.motor.phase_inductance_h, 4e-3, 1e-12);
  EXPECT_NE(yaml.find("starting point"), std::string::npos);
  EXPECT_NE(yaml.find("Predicted step"), std::string::npos);
}

namespace {
// A profile with only this motor block (a profile needs a parameters map).
std::string motor_yaml(const std::string& motor_lines) {
  return "name: m\nmotor:\n" + motor_lines + "parameters:\n  NVKQP: 50\n";
}
}  // namespace

// Data sheets give R and L between two leads: the loader halves them (the equivalent star).
TEST(MotorData, LineToLineValuesGiveHalfAsPhaseValues) {
  const auto p =
      load(motor_yaml("  line_to_line_resistance: 4 ohm\n  line_to_line_inductance: 12 mH\n  poles: 8\n"));
  EXPECT_DOUBLE_EQ(*p.motor.phase_resistance_ohm, 2.0);
  EXPECT_DOUBLE_EQ(*p.motor.phase_inductance_h, 6e-3);
  EXPECT_EQ(*p.motor.poles, 8);
  // Written back as given, and loading that again gives the same motor.
  const auto again = load(to_yaml(p, db()));
  EXPECT_DOUBLE_EQ(*again.motor.line_to_line_resistance_ohm, 4.0);
  EXPECT_DOUBLE_EQ(*again.motor.phase_inductance_h, 6e-3);
  EXPECT_EQ(*again.motor.poles, 8);
}

TEST(MotorData, PhaseAndLineToLineMustAgree) {
  EXPECT_EQ(load_error(motor_yaml("  phase_resistance: 4 ohm\n  line_to_line_resistance: 4 ohm\n")).key(),
            "phase_resistance");
  const auto p = load(motor_yaml("  phase_inductance: 6 mH\n  line_to_line_inductance: 12 mH\n"));
  EXPECT_DOUBLE_EQ(*p.motor.phase_inductance_h, 6e-3);
}

TEST(MotorData, PolesAndPolePairsAreWholeAndAgree) {
  EXPECT_EQ(*load(motor_yaml("  pole_pairs: 5\n")).motor.poles, 10);
  EXPECT_EQ(load_error(motor_yaml("  poles: 7\n")).key(), "poles");
  EXPECT_EQ(load_error(motor_yaml("  poles: 2.5\n")).key(), "poles");
  EXPECT_EQ(load_error(motor_yaml("  poles: 0\n")).key(), "poles");
  EXPECT_EQ(load_error(motor_yaml("  poles: 8\n  pole_pairs: 3\n")).key(), "pole_pairs");
  EXPECT_EQ(*load(motor_yaml("  poles: 8\n  pole_pairs: 4\n")).motor.poles, 8);
}

// profile validate judges a profile's gains on its own motor with the model tune uses.
TEST(MotorData, ValidateRefusesGainsTheModelCallsUnstable) {
  const std::string motor =
      "motor:\n  phase_resistance: 0.6 ohm\n  phase_inductance: 1.75 mH\nsupply:\n  bus_voltage: 320 V\n";
  // What `i20 tune ... --bandwidth 2000Hz --force` computes for this motor at 15 A.
  TuneRequest r;
  r.motor = {0.6, 1.75e-3};
  r.max_current_a = 15.0;
  r.bus_voltage_v = 320.0;
  r.bandwidth_hz = 2000.0;
  const auto hot = tune(r, db());
  r.bandwidth_hz = 400.0;
  const auto calm = tune(r, db());
  const auto gains = [](const TuneResult& t) {
    return "  NVMAXCURRENT: 15 A\n  NVKQP: " + std::to_string(t.kp) + "\n  NVKDP: " + std::to_string(t.kp) +
           "\n  NVKQI: " + std::to_string(t.ki) + "\n  NVKDI: " + std::to_string(t.ki) + "\n";
  };
  auto findings = validate(load(with_params(gains(hot), motor)), db());
  EXPECT_TRUE(has_rule(findings, "loop-unstable", Severity::Error)) << dump(findings);
  findings = validate(load(with_params(gains(hot), motor)), db(), {nullptr, true, std::nullopt});
  EXPECT_TRUE(has_rule(findings, "loop-unstable", Severity::Warning)) << "forced: " << dump(findings);
  findings = validate(load(with_params(gains(calm), motor)), db());
  EXPECT_FALSE(has_rule(findings, "loop-unstable")) << dump(findings);
  // Without the motor's R and L the model has nothing to judge.
  findings = validate(load(with_params(gains(hot))), db());
  EXPECT_FALSE(has_rule(findings, "loop-unstable")) << dump(findings);
}
