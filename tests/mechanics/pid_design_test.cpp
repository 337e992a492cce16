// SPDX-License-Identifier: GPL-2.0-or-later
// LinuxCNC pid gains designed from an axis's mechanics (lib/mechanics/pid_design), judged in
// the time domain on the motor model (lib/mechanics/axis_simulation: LinuxCNC's pid each servo
// period, its output one period late, as the design assumes). The stated gain margin must be
// where the loop really turns unstable, and a trapezoidal move must follow.
#include "mechanics/pid_design.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <vector>

#include "mechanics/axis_simulation.hpp"
#include "motor/motor.hpp"

using namespace i20;

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kUnitsPerRad = 5 / kTwoPi;  // a 5 mm screw, machine units in mm

motor::MotorParams axis_truth(double load_ratio, double coulomb, double gravity) {
  motor::MotorParams p;
  p.pole_pairs = 4;
  p.winding = {1.9, 6.2e-3};
  p.torque_constant_nm_per_a = 0.45;
  p.inertia_kgm2 = 0.6e-4;
  p.coulomb_nm = coulomb;
  p.load_nm = gravity;
  p.machine.lead_m_per_turn = 0.005;
  p.machine.mass_kg = load_ratio * p.inertia_kgm2 / std::pow(0.005 / kTwoPi, 2);
  p.encoder = motor::EncoderDescription{};
  p.encoder->counts_per_turn = 10000;
  return p;
}

// The rigid model with the resonance as a ceiling only (no rotor inertia given).
mechanics::AxisModel model_of(const motor::MotorParams& p) {
  auto a = mechanics::axis_model_of(p, kUnitsPerRad, 10);
  a.rotor_inertia_kgm2 = 0;
  return a;
}

}  // namespace

TEST(PidDesign, TheMarginsAskedForAreTheMarginsMeasured) {
  for (double ratio : {1.0, 5.0, 20.0}) {
    const auto axis = model_of(axis_truth(ratio, 0.02, 0.3));
    const auto g = mechanics::design_pid(axis);
    SCOPED_TRACE("load ratio " + std::to_string(ratio));
    EXPECT_GE(g.phase_margin_deg, 45.0);
    EXPECT_GE(g.gain_margin_db, 8.0);
    EXPECT_GT(g.crossover_hz, 10.0);
    double crossover = 0;
    const auto again = mechanics::measure_margins(axis, {}, g, &crossover);
    EXPECT_NEAR(again.phase_deg, g.phase_margin_deg, 1e-9);
    EXPECT_NEAR(crossover, g.crossover_hz, 1e-9);
    // Feedforward from the model: FF2 = J / (Kt r), bias = G / Kt.
    EXPECT_NEAR(g.ff2, axis.inertia_kgm2 / (0.45 * kUnitsPerRad), 1e-12);
    EXPECT_NEAR(g.bias, 0.3 / 0.45, 1e-12);
    EXPECT_EQ(g.maxoutput, 10.0);
  }
}

// The gain margin in the time domain: with P, I and D scaled to 0.8 of the margin a 0.1 mm
// step rings down to the encoder's resolution (0.5 um); at 1.25 of it the loop rings on,
// bounded only by the 10 A output limit. A frictionless, gravity-free axis keeps the loop
// linear so that nothing but the gain decides. (Scanned while building this: settled at 1.0
// of the margin, rang on from 1.1.)
TEST(PidDesign, TheLoopTurnsUnstableWhereTheGainMarginSays) {
  const auto truth = axis_truth(5, 0, 0);
  const auto g = mechanics::design_pid(model_of(truth));
  const double margin = std::pow(10, g.gain_margin_db / 20);
  const mechanics::MoveProfile step{.distance = 0.1, .speed = 1000, .accel = 1e6, .dwell_s = 1.0};
  const auto below = mechanics::simulate_move(truth, g, kUnitsPerRad, step, {}, 0.8 * margin);
  const auto above = mechanics::simulate_move(truth, g, kUnitsPerRad, step, {}, 1.25 * margin);
  EXPECT_LE(below.rest_error, 0.002) << "0.8 x the margin rang on";
  EXPECT_GE(above.rest_error, 0.010) << "1.25 x the margin settled";
}

// A trapezoidal move (100 mm at 100 mm/s, 1 m/s^2, out and back) on a vertical axis with
// friction: the designed gains follow it and come to rest, every load ratio.
TEST(PidDesign, TheDesignedGainsFollowATrapezoidalMove) {
  for (double ratio : {1.0, 5.0, 20.0}) {
    const auto truth = axis_truth(ratio, 0.03, 0.3);
    const auto g = mechanics::design_pid(model_of(truth));
    const mechanics::MoveProfile move{.distance = 100, .speed = 100, .accel = 1000, .dwell_s = 0.5};
    const auto trace = mechanics::simulate_move(truth, g, kUnitsPerRad, move);
    SCOPED_TRACE("load ratio " + std::to_string(ratio));
    std::printf(
        "load ratio %.0f: crossover %.1f Hz, following error peak %.1f um, RMS %.1f um, at rest %.1f um\n",
        ratio, g.crossover_hz, trace.peak_error * 1e3, trace.rms_error * 1e3, trace.rest_error * 1e3);
    EXPECT_LT(trace.peak_error, 0.050) << "following error while moving";
    EXPECT_LT(trace.rest_error, 0.005) << "at rest after the move";
    EXPECT_EQ(trace.points.size(), static_cast<std::size_t>(std::ceil(move.duration_s() / 1e-3)));
  }
}

TEST(PidDesign, TheMoveIsOutAndBackAsLimit3WouldGiveIt) {
  const mechanics::MoveProfile move{.distance = 10, .speed = 20, .accel = 500, .dwell_s = 0.5};
  // Each leg: 0.04 s to 20 mm/s, 0.46 s at speed, 0.04 s to rest: 0.54 s; then 0.5 s still.
  EXPECT_NEAR(move.duration_s(), 2 * (0.54 + 0.5), 1e-9);
  EXPECT_NEAR(move.position(0.02), 0.5 * 500 * 0.02 * 0.02, 1e-12);
  EXPECT_NEAR(move.position(0.54), 10, 1e-12);
  EXPECT_NEAR(move.position(1.04 + 0.27), 5, 1e-9);
  EXPECT_NEAR(move.position(2.08), 0, 1e-12);
  const mechanics::MoveProfile short_move{.distance = -0.1, .speed = 20, .accel = 500, .dwell_s = 0};
  EXPECT_NEAR(short_move.position(short_move.duration_s() / 2), -0.1, 1e-12);  // a triangle, reaching -0.1
}

TEST(PidDesign, AResonanceCapsTheCrossoverAFifthBelowIt) {
  auto axis = model_of(axis_truth(5, 0.02, 0));
  const double free = mechanics::design_pid(axis).crossover_hz;
  axis.resonance_hz = 60;
  const auto g = mechanics::design_pid(axis);
  EXPECT_LE(g.crossover_hz, 60.0 / 5 * 1.05);
  EXPECT_LT(g.crossover_hz, free);
  EXPECT_EQ(g.limited_by, "the resonance");
}

TEST(PidDesign, TheIniSectionIsWhatIHalReads) {
  const auto g = mechanics::design_pid(model_of(axis_truth(5, 0.02, 0.3)));
  const std::string ini = mechanics::ini_section(2, g);
  EXPECT_EQ(ini.rfind("[JOINT_2]\n", 0), 0u);
  for (const char* key : {"\nP = ", "\nI = ", "\nD = ", "\nFF0 = 0\n",
                          "\nFF1 = ", "\nFF2 = ", "\nBIAS = ", "\nDEADBAND = 0\n", "phase margin"})
    EXPECT_NE(ini.find(key), std::string::npos) << key << " in " << ini;
}

TEST(PidDesign, AModelThatCannotMakeALoopIsRefused) {
  auto axis = model_of(axis_truth(5, 0.02, 0));
  axis.units_per_rad = 0;
  EXPECT_THROW(mechanics::design_pid(axis), mechanics::IdentifyError);
  axis = model_of(axis_truth(5, 0.02, 0));
  EXPECT_THROW(mechanics::design_pid(axis, {.servo_period_s = 0}), mechanics::IdentifyError);
}

namespace {

// The vertical screw axis's mechanics (motors/vertical-screw-axis.yaml): a load 0.75 of the
// rotor's inertia behind a coupling ringing at 180 Hz with 5% damping, 0.3 Nm of weight.
motor::MotorParams coupled_truth(double coulomb = 0.02) {
  auto p = axis_truth(0.75, coulomb, 0.3);
  const double load = motor::reflected_load_inertia(p);
  const double mobility = 1 / p.inertia_kgm2 + 1 / load;
  p.machine.stiffness_nm_per_rad = std::pow(kTwoPi * 180, 2) / mobility;
  p.machine.damping_nm_per_rad_s = 2 * 0.05 * std::sqrt(p.machine.stiffness_nm_per_rad / mobility);
  return p;
}

std::complex<double> biquad_at(const mechanics::Notch& n, double hz, double period_s) {
  const auto zi = std::exp(std::complex<double>(0, -kTwoPi * hz * period_s));
  return (n.n0 + n.n1 * zi + n.n2 * zi * zi) / (1.0 + n.d1 * zi + n.d2 * zi * zi);
}

}  // namespace

// LinuxCNC's biquad (type 0) computes y = (n0 x + n1 x' + n2 x'') - d1 y' - d2 y'': with the
// design's coefficients it passes DC and the Nyquist rate and nothing at the centre. (halrun,
// biquad type 0 with the coefficients `i20 pid --notch` gives the vertical screw axis, 179.9 Hz
// q 2: DC passed at gain 1, siggen's 179.9 Hz sine out at 0.0006 of its amplitude.)
TEST(PidDesign, TheNotchIsABiquadWithNothingThroughAtItsCentre) {
  const auto n = mechanics::notch_filter(180, 2, 1e-3);
  EXPECT_NEAR(std::abs(biquad_at(n, 0, 1e-3)), 1, 1e-12);
  EXPECT_NEAR(std::abs(biquad_at(n, 500, 1e-3)), 1, 1e-12);
  EXPECT_LT(std::abs(biquad_at(n, 180, 1e-3)), 1e-9);
  EXPECT_LT(std::abs(biquad_at(n, 179.9, 1e-3)), 5e-3);  // 0.1 Hz off the centre
  EXPECT_GT(std::abs(biquad_at(n, 90, 1e-3)), 0.8);      // q 2: 90 Hz is well outside the band
  EXPECT_NEAR(n.n0, n.n2, 1e-15);
  EXPECT_NEAR(n.n1, n.d1, 1e-15);
  EXPECT_THROW(mechanics::notch_filter(500, 2, 1e-3), mechanics::IdentifyError);  // the Nyquist rate
  EXPECT_THROW(mechanics::notch_filter(180, 0, 1e-3), mechanics::IdentifyError);
}

// Two masses: without a notch the loop keeps its margins over the resonance's peak; with one
// allowed, the notch at the resonance lets it cross over higher, keeps the margins with the
// resonance 10% off either way, and the axis follows the move closer and still comes to rest.
TEST(PidDesign, ANotchAtTheResonanceLetsTheLoopCrossOverHigher) {
  const auto truth = coupled_truth();
  const auto axis = mechanics::axis_model_of(truth, kUnitsPerRad, 10);
  ASSERT_TRUE(axis.resonance_hz);
  EXPECT_NEAR(*axis.resonance_hz, 180, 0.1);
  const auto plain = mechanics::design_pid(axis);
  EXPECT_FALSE(plain.notch) << "no notch unless the HAL runs one";
  const auto notched = mechanics::design_pid(axis, {}, {}, mechanics::NotchUse::WhereItHelps);
  ASSERT_TRUE(notched.notch);
  EXPECT_NEAR(notched.notch->frequency_hz, 180, 0.1);
  EXPECT_GT(notched.crossover_hz, 1.4 * plain.crossover_hz);
  for (const double scale : {0.9, 1.0, 1.1}) {
    auto shifted = axis;
    shifted.resonance_hz = *axis.resonance_hz * scale;
    const auto m = mechanics::measure_margins(shifted, {}, notched);
    SCOPED_TRACE("resonance x" + std::to_string(scale));
    EXPECT_GE(m.phase_deg, 45.0);
    EXPECT_GE(m.gain_db, 8.0);
  }
  const mechanics::MoveProfile move{.distance = 10, .speed = 20, .accel = 500, .dwell_s = 0.5};
  const auto without = mechanics::simulate_move(truth, plain, kUnitsPerRad, move);
  const auto with = mechanics::simulate_move(truth, notched, kUnitsPerRad, move);
  std::printf(
      "180 Hz coupling: crossover %.1f Hz without a notch, %.1f Hz with (q %.1f); peak %.1f um, %.1f um\n",
      plain.crossover_hz, notched.crossover_hz, notched.notch->q, without.peak_error * 1e3,
      with.peak_error * 1e3);
  EXPECT_LT(with.peak_error, 0.75 * without.peak_error);
  EXPECT_LT(with.rest_error, 0.01);  // mm: at rest within 10 um
  const std::string ini = mechanics::ini_section(0, notched);
  for (const char* key :
       {"\nNOTCH_N0 = ", "\nNOTCH_N1 = ", "\nNOTCH_N2 = ", "\nNOTCH_D1 = ", "\nNOTCH_D2 = "})
    EXPECT_NE(ini.find(key), std::string::npos) << key << " in " << ini;
  EXPECT_EQ(mechanics::ini_section(0, plain).find("NOTCH"), std::string::npos);
}

// The simulated axis's current passes the notch as LinuxCNC's biquad would pass it: with P, I
// and D doubled (6 dB, within the notched loop's 14.6 dB at the nominal resonance) the axis
// still comes to rest through the notch, and rings without it (its loop then has -2.9 dB).
TEST(PidDesign, TheSimulatedLoopRunsTheNotch) {
  const auto truth = coupled_truth(0);  // Coulomb friction would quench a small ringing
  const auto axis = mechanics::axis_model_of(truth, kUnitsPerRad, 10);
  auto g = mechanics::design_pid(axis, {}, {}, mechanics::NotchUse::WhereItHelps);
  ASSERT_TRUE(g.notch);
  const mechanics::MoveProfile move{.distance = 1, .speed = 20, .accel = 500, .dwell_s = 0.5};
  const auto through = mechanics::simulate_move(truth, g, kUnitsPerRad, move, {}, 2.0);
  g.notch.reset();
  EXPECT_LT(mechanics::measure_margins(axis, {}, g).gain_db, 8.0) << "the notch is what gives the margin";
  const auto without = mechanics::simulate_move(truth, g, kUnitsPerRad, move, {}, 2.0);
  EXPECT_LT(through.rest_error, 0.005);  // mm
  EXPECT_GT(without.rest_error, 0.05) << "without the notch, gains 6 dB up should ring";
}
