// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 29's figure: how fast the motor model runs against real time, at the PWM rate
// (12 kHz, 4 sub-steps per period), alone and inside a virtual 8I20 that a 1 kHz servo
// thread feeds ANGLE and QSETPOINT over LBP. The server must keep up with a 1 kHz servo
// period with margin on a 2-core machine; the real-time factor says by how much.
//
// Simulated figures: the model against the wall clock of whatever machine runs this.
//
//   i20-bench-motor [SIMULATED_SECONDS]      default 5
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

#include "lbp/crc8.hpp"
#include "motor/motor.hpp"
#include "sim/virtual_8i20.hpp"

namespace {

using namespace i20;
using Wall = std::chrono::steady_clock;

motor::MotorParams servo() {
  motor::MotorParams p;
  p.name = "small servo";
  p.pole_pairs = 4;
  p.winding = {0.6, 1.75e-3};
  p.torque_constant_nm_per_a = 0.2;
  p.inertia_kgm2 = 1.2e-5;
  p.viscous_nm_per_rad_s = 1e-3;
  p.coulomb_nm = 0.01;
  p.cogging_nm = 0.004;
  p.cogging_periods_per_turn = 24;
  return p;
}

double seconds_since(Wall::time_point t0) {
  return std::chrono::duration<double>(Wall::now() - t0).count();
}

void report(const char* what, double simulated_s, double wall_s, double periods_per_s, int substeps) {
  const double factor = simulated_s / wall_s;
  std::printf(
      "%-46s %8.3f s simulated in %7.3f s: %6.1fx real time, %9.0f periods/s (%9.0f sub-steps/s); "
      "one axis in real time takes %.2f%% of a core\n",
      what, simulated_s, wall_s, factor, periods_per_s * factor, periods_per_s * factor * substeps,
      100.0 / factor);
}

// The model alone, ideal commutation, a current reversing every 50 ms so it keeps working.
void bench_model(double simulated_s) {
  motor::Motor m(servo());
  motor::DriveCommand d;
  d.output_on = true;
  d.frame_follows_rotor = true;
  d.bus_voltage_v = 320;
  d.d_gains = d.q_gains = motor::physical_gains(50, 150000, 10, 320);
  const int chunks = static_cast<int>(simulated_s * 1000);
  const auto t0 = Wall::now();
  for (int k = 0; k < chunks; ++k) {
    d.current_a = {0, (k / 50) % 2 ? -2.0 : 2.0};
    m.command(d);
    m.step(0.001);
  }
  const double wall = seconds_since(t0);
  report("motor model alone (1 ms steps)", m.state().time_s, wall, 1.0 / m.period_s(), 4);
  if (!std::isfinite(m.state().speed_rad_s)) std::exit(1);
}

lbp::Bytes write32(std::uint16_t address, std::uint32_t value) {
  lbp::Bytes cmd{0x66, static_cast<lbp::Byte>(address), static_cast<lbp::Byte>(address >> 8)};
  for (int k = 0; k < 4; ++k) cmd.push_back(static_cast<lbp::Byte>(value >> (8 * k)));
  cmd.push_back(lbp::crc8(cmd));
  return cmd;
}

// The virtual 8I20 in operate mode with the motor, a 1 kHz host writing ANGLE (from the
// rotor) and QSETPOINT, and reading the reply, on the simulator's clock.
void bench_card(double simulated_s) {
  sim::DeviceOptions o;
  o.mode = sim::FramingMode::Operate;
  o.motor = servo();
  auto t = sim::Clock::time_point{} + std::chrono::hours(1);
  sim::Virtual8i20 card(o, t);
  const auto angle_address = card.amplifier().map().at("ANGLE").address;
  const int periods = static_cast<int>(simulated_s * 1000);
  std::size_t replies = 0;
  const auto t0 = Wall::now();
  for (int k = 0; k < periods; ++k) {
    const double electrical = card.motor()->state().electrical_angle_rad;
    const auto angle =
        static_cast<std::uint32_t>(std::lround(electrical / (2 * std::numbers::pi) * 65536)) & 0xFFFF;
    const std::int16_t setpoint = (k / 50) % 2 ? -6553 : 6553;
    card.receive(write32(angle_address,
                         static_cast<std::uint32_t>(static_cast<std::uint16_t>(setpoint)) << 16 | angle),
                 t);
    t += std::chrono::microseconds(1000);
    card.advance(t);
    replies += card.take_output().size();
  }
  const double wall = seconds_since(t0);
  report("virtual 8I20 + motor, 1 kHz ANGLE/QSETPOINT", card.motor()->state().time_s, wall,
         1.0 / card.motor()->period_s(), 4);
  if (card.amplifier().fault() != 0 || replies == 0) {
    std::fprintf(stderr, "the card faulted (0x%04X) or did not answer\n", card.amplifier().fault());
    std::exit(1);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const double simulated_s = argc > 1 ? std::atof(argv[1]) : 5.0;
  if (!(simulated_s > 0)) {
    std::fprintf(stderr, "usage: i20-bench-motor [SIMULATED_SECONDS]\n");
    return 2;
  }
  std::printf(
      "Motor model at the 8I20's default 12 kHz PWM, 4 sub-steps per period (simulated, on this machine):\n");
  bench_model(simulated_s);
  bench_card(simulated_s);
  return 0;
}
