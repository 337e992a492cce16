// SPDX-License-Identifier: GPL-2.0-or-later
// Between tuning and profiles: the request from a motor profile's metadata, and the
// result as a profile ready to validate and apply.
#pragma once

#include <chrono>
#include <string>

#include "params/param_db.hpp"
#include "profile/profile.hpp"
#include "profile/step_response.hpp"
#include "profile/tune.hpp"

namespace i20::profile {

struct TuningProfileOptions {
  std::string name = "tuning";
  MotorInfo motor;                 // make, model and ratings to carry over (R and L come from the request)
  std::string supply_description;  // e.g. "240 V line, bridge rectifier"
  std::chrono::system_clock::time_point when = std::chrono::system_clock::now();
};

// NVMAXCURRENT, NVKQP = NVKDP and NVKQI = NVKDI (the gains only hold for that MAXCURRENT),
// with the motor, the bus voltage, the basis of the numbers and the predicted step in the
// metadata. Applies to the EEPROM; retarget() it to try it live first.
Profile tuning_profile(const TuneRequest& request, const TuneResult& result, const StepResponse& predicted,
                       const params::ParamDb& db, const TuningProfileOptions& options = {});

// The motor's phase R and L, MAXCURRENT (the profile's NVMAXCURRENT or MAXCURRENT) and the
// supply's bus_voltage from a profile. Throws TuneError naming whatever is missing.
TuneRequest tune_request_from(const Profile& profile, const params::ParamDb& db, double bandwidth_hz);

}  // namespace i20::profile
