// SPDX-License-Identifier: GPL-2.0-or-later
// A virtual 7I92T servo card on loopback UDP with an 8I20 driving a motor on axis 0, and
// the truth the commissioning should find for it.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "commission/hall_table.hpp"
#include "ethsim/server.hpp"
#include "motor/loader.hpp"
#include "motor/sensors.hpp"
#include "ops/commission/commission.hpp"
#include "ops/core/session.hpp"

namespace i20::test {

struct MotorSpec {
  int pole_pairs = 4;
  std::int64_t counts_per_turn = 4000;
  int direction = 1;
  double index_deg = 30;  // mechanical
  std::string halls = "  pattern: 25\n";
  double load_nm = 0;
  double cogging_nm = 0;
  bool brake = false;
  std::string extra;

  std::string yaml() const {
    std::string y = std::string("name: test\npole_pairs: ") + std::to_string(pole_pairs);
    y += "\nresistance: 1.9ohm\ninductance: 6.2mH\ntorque_constant: 0.45Nm/A\ninertia: 0.6kgcm^2\n";
    y += "friction:\n  viscous: 0.05mNm/(rad/s)\n  coulomb: 0.02Nm\n";
    if (cogging_nm > 0)
      y += std::string("cogging:\n  torque: ") + std::to_string(cogging_nm) + "Nm\n  periods_per_turn: 36\n";
    y += std::string("load: ") + std::to_string(load_nm) + "Nm\n";
    y += "brake:\n  torque: 3Nm\n  engaged: ";
    y += brake ? "true\n" : "false\n";
    y += std::string("channel: 0\nencoder:\n  counts_per_turn: ") + std::to_string(counts_per_turn);
    y += std::string("\n  direction: ") + std::to_string(direction);
    y += std::string("\n  index_angle: ") + std::to_string(index_deg) + "deg\n";
    if (!halls.empty()) y += "halls:\n" + halls;
    y += extra;
    return y;
  }
};

// bldc's pattern as the tool sees it: hall1..3 on inputs 0, 1, 2 of the axis.
inline std::optional<int> true_pattern(const motor::MotorParams& params) {
  if (!params.halls) return std::nullopt;
  commission::HallSequence seq;
  for (int k = 0; k < 6; ++k) {
    const unsigned code = motor::hall_code(*params.halls, k * std::numbers::pi / 3.0);
    unsigned seen = 0;
    for (int h = 0; h < 3; ++h)
      if (code >> (2 - h) & 1u) seen |= 4u >> params.halls->inputs[static_cast<std::size_t>(h)];
    seq.code_at_sector[static_cast<std::size_t>(k)] = static_cast<commission::HallCode>(seen);
  }
  const auto row = commission::find_hall_row(seq);
  return row ? commission::hall_table()[*row].bldc_pattern : std::nullopt;
}

// The rotor's electrical angle (degrees, [0, 360)) where the index is.
inline double true_index_electrical_deg(const motor::MotorParams& params) {
  const double turns = params.pole_pairs * params.encoder->index_angle_rad / (2 * std::numbers::pi);
  return (turns - std::floor(turns)) * 360.0;
}

class VirtualAxis {
 public:
  explicit VirtualAxis(const MotorSpec& spec) : params_(motor::parse_motor(spec.yaml(), "test motor")) {
    ethsim::ServerOptions o;
    o.listen = eth::HostPort{.ip = "127.0.0.1", .port = 0};
    o.card = ethsim::BoardKind::I7i92t;
    o.config = ethsim::BoardConfig::preset_7i92t_servo();
    o.amplifiers = {{0, 0}};
    o.motors = {params_};
    server_ = std::make_unique<ethsim::BoardServer>(o);
    server_->start();
  }
  ~VirtualAxis() { server_->stop(); }

  ops::SessionOptions session_options() const {
    ops::SessionOptions so;
    so.target.eth = std::string("127.0.0.1:") + std::to_string(server_->address().port);
    return so;
  }
  ethsim::BoardServer& server() { return *server_; }
  const motor::MotorParams& params() const { return params_; }
  // The q current the 8I20 drives now (amps, from its last QSETPOINT).
  double qsetpoint() {
    return server_->with_card([&](ethsim::VirtualBoard& board) {
      return static_cast<double>(
          static_cast<std::int16_t>(server_->amplifier(board, 0, 0)->amplifier().value("QSETPOINT")));
    });
  }

 private:
  motor::MotorParams params_;
  std::unique_ptr<ethsim::BoardServer> server_;
};

// Fast settings for tests: a short sweep, quick.
inline ops::CommissionOptions quick_options() {
  ops::CommissionOptions o;
  o.align_s = 0.3;
  o.ramp_s = 0.15;
  o.sweep_turns = 2.0;
  o.turns_per_s = 4.0;
  o.time_limit_s = 20;
  return o;
}

}  // namespace i20::test
