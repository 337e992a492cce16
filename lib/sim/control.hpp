// SPDX-License-Identifier: GPL-2.0-or-later
// The simulator's control language: one command per line, used by i20sim's stdin and
// control FIFO and by SimStream::control(), so the world and the injection switches can
// change while a client talks to the card. Replies are one line ("ok", values, or what
// was wrong). `help` lists everything; control_help() returns the same text.
//
//   busv 320              bus voltage in volts        temp 45         card temperature, C
//   enable on|off         enable input                noise busv|temp AMPLITUDE
//   seed N                noise seed                  fault NAME|BIT on|off  (hardware cause)
//   corrupt RATE          reply bytes corrupted, 0..1 drop RATE       replies lost, 0..1
//   delay MS              extra reply latency         reset-after N|off
//   clearfault-stuck on|off                           eeprom-power-loss off|lost|torn
//   mute-after N|off      answer N more commands, then go silent
//   power off|on|cycle    get NAME    set NAME VALUE  show    help
//   motor KEY VALUE       change the attached motor live (motor load 0.3Nm: a load step)
//   motor fault hall-stuck|encoder-lost on|off        motor  (its state)
#pragma once

#include <string>
#include <string_view>

#include "sim/virtual_8i20.hpp"

namespace i20::sim {

// Applies one control line at `now`. Throws ControlError with a one-line reason and the
// expected form for anything it does not understand. Blank lines and # comments: "".
std::string apply_control(Virtual8i20& card, std::string_view line, Clock::time_point now);

// The commands and their forms, one per line.
std::string control_help();

// "busv=320.00V temp=35.00C enable=on fault=0x0000 status=0x0040 ...": the state at a glance.
std::string describe_state(Virtual8i20& card);

// "motor_angle=0.125000turns speed=300.0rpm electrical=180.0deg encoder=1250 halls=110 iu=...":
// mechanical angle, speed, electrical angle, encoder count, Hall code, phase and dq
// currents, torque, whether the bridge is on, load and brake.
std::string describe_motor(const motor::Motor& motor);

}  // namespace i20::sim
