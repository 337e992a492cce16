// SPDX-License-Identifier: GPL-2.0-or-later
// i20 pid: LinuxCNC pid gains for an 8I20 axis, designed to stated margins from its
// mechanics (lib/mechanics/pid_design), as the [JOINT_n] lines `i20 hal`'s file reads. The
// mechanics come from a motor file (the virtual axis's truth, to rehearse) or from values the
// user measured. Needs no card.
#pragma once

#include <optional>
#include <string>

#include "mechanics/axis_simulation.hpp"
#include "mechanics/pid_design.hpp"
#include "motor/params.hpp"

namespace i20::ops {

struct AxisPidRequest {
  mechanics::AxisModel axis;
  mechanics::LoopTiming timing;
  mechanics::Margins margins;
  int joint = 0;
  // Never unless the HAL runs the notch after pid (i20 hal --notch).
  mechanics::NotchUse notch = mechanics::NotchUse::Never;
  // To see the gains at work: the motor model (a motor file with its machine) follows this
  // move under LinuxCNC's pid with the designed gains.
  std::optional<motor::MotorParams> truth;
  std::optional<mechanics::MoveProfile> move;
};

struct AxisPidResult {
  mechanics::PidGains gains;
  std::string ini;                            // the [JOINT_n] section
  std::optional<mechanics::MoveTrace> trace;  // with truth and move
};

// Refuses (UsageError) a model that cannot be an axis: non-positive inertia, torque constant,
// scale, current or period, negative friction, a delay past the period, margins outside
// 30-80 degrees and 3-20 dB, a move without a motor to make it or with a non-positive
// distance, speed or acceleration. Fails (mechanics::IdentifyError) when no crossover keeps
// the margins.
AxisPidResult design_axis_pid(const AxisPidRequest& request);

// The axis a motor file describes: the rotor and its reflected load, friction, the load torque
// as the bias, the torque constant, the lead in machine units (`units_per_metre`: 1000 for an
// INI in mm) and the coupling's resonance. UsageError when the file has no machine.lead.
mechanics::AxisModel axis_from_motor(const motor::MotorParams& motor, double units_per_metre,
                                     double max_current_a);

}  // namespace i20::ops
