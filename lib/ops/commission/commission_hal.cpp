// SPDX-License-Identifier: GPL-2.0-or-later
// The HAL fragment `i20 commission -o FILE.hal` writes (names: docs/linuxcnc-hal.md).
#include <algorithm>
#include <cctype>
#include <sstream>

#include "commission/format.hpp"
#include "linuxcnc/hal_generate.hpp"
#include "linuxcnc/index_capture.hpp"
#include "ops/commission/commission.hpp"

namespace i20::ops {

namespace {

std::string board_key(const std::string& card_name) {
  std::string key = card_name;
  std::transform(key.begin(), key.end(), key.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return key;
}

std::string two_digits(unsigned n) {
  std::string s = n < 10 ? "0" : "";
  s += std::to_string(n);
  return s;
}

}  // namespace

std::string commission_hal_fragment(const CommissionReport& report) {
  if (report.stop != StopReason::Completed || !report.bldc || !report.check || !report.check->passed)
    throw Error("no HAL fragment: the commissioning did not complete and pass its closed-loop check",
                ErrorKind::Refused);
  const auto& b = *report.bldc;
  if (report.hall_pins.size() != 3 || !b.pattern)
    throw Error(
        "no HAL fragment: bldc needs Hall sensors (cfg qh/qhi) to start an 8I20 axis; its q modes without h "
        "align the rotor through bldc's own A/B/C outputs, which the 8I20 does not take",
        ErrorKind::Refused);
  if (!b.poles || !b.scale)
    throw Error("no HAL fragment: the poles or the scale are unknown", ErrorKind::Refused);
  const bool index = b.encoder_offset.has_value();
  const std::string board = linuxcnc::hm2_device(board_key(report.plan.preflight.board));
  const auto& t = report.plan.preflight.target;
  const std::string amp = board + ".8i20." + std::to_string(t.sserial_port) + "." + std::to_string(t.channel);
  const std::string encoder = board + ".encoder." + two_digits(report.encoder_instance.value_or(0));
  const std::string cfg = index ? "qhi" : "qh";

  std::ostringstream out;
  out << "# bldc setup found by i20 commission for the 8I20 at " << t.url() << " ("
      << report.plan.preflight.board << ").\n"
      << "# Load hostmot2 and hm2_eth for this card and create servo-thread first; source this file after\n"
      << "# addf BOARD.read and before addf BOARD.write (bldc runs between them); then feed the\n"
      << "# torque command (amps) into bldc.0.value. Commutation: "
      << (index ? "Halls until the index, then the encoder" : "Halls and the encoder") << ".\n"
      << "loadrt bldc cfg=" << cfg << "\n"
      << "setp bldc.0.pattern " << *b.pattern << "\n"
      << "setp bldc.0.poles " << *b.poles << "\n"
      << "setp bldc.0.scale " << *b.scale << "\n";
  if (index) out << "setp bldc.0.encoder-offset " << *b.encoder_offset << "\n";
  for (std::size_t h = 0; h < 3; ++h)
    out << "net bldc0-hall" << h + 1 << " " << board << "." << report.hall_pins[h] << " => bldc.0.hall"
        << h + 1 << "\n";
  const auto capture = linuxcnc::index_capture("bldc0-", 0);
  if (index) {
    out << "# The index capture uses mux_generic: if your configuration loads it already, add ss2 to its\n"
           "# config string and use that instance's number here instead of mux-gen.00.\n"
        << linuxcnc::index_capture_loads({capture}) << "net bldc0-index-enable " << encoder
        << ".index-enable <=> bldc.0.index-enable\n"
        << linuxcnc::index_capture_nets(capture, encoder, "bldc.0", "bldc0-", "bldc0-index-enable");
  } else {
    out << "net bldc0-rawcounts " << encoder << ".rawcounts => bldc.0.rawcounts\n";
  }
  out << "# rotor-angle, not phase-angle: the 8I20 adds its own lead\n"
      << "net bldc0-rotor-angle bldc.0.rotor-angle => " << amp << ".angle\n"
      << "# current in amps (hostmot2 scales it by the card's MAXCURRENT)\n"
      << "net bldc0-current bldc.0.out => " << amp << ".current\n";
  if (index) out << linuxcnc::index_capture_functions(capture);
  out << "addf bldc.0 servo-thread\n";
  return out.str();
}

}  // namespace i20::ops
