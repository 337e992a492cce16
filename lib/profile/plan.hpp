// SPDX-License-Identifier: GPL-2.0-or-later
// What an apply will write, and in which order.
//
// Only cells that differ from the card are written: EEPROM cells wear out and each write
// takes milliseconds (docs/facts.md s7), so applying the same profile twice writes nothing.
#pragma once

#include <vector>

#include "params/param_db.hpp"
#include "profile/raw_values.hpp"
#include "profile/diff.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

struct Plan {
  std::vector<DiffRow> steps;      // cells to write, in write order
  std::vector<DiffRow> unchanged;  // cells that already hold the profile's value
  bool reset_needed = false;       // an EEPROM cell changes: it takes effect after reset

  bool empty() const { return steps.empty(); }
};

// Throws ProfileError if the profile writes a cell twice or a target cannot be met.
Plan make_plan(const Profile& profile, const params::ParamDb& db, const RawValues& card);

// The write order, chosen so that every intermediate state is as safe as the start and the
// end, should the apply stop half way (power loss, link failure):
//  - EEPROM cells first, then working cells: the drive's live behaviour changes last;
//  - within each, a MAXCURRENT decrease first and a MAXCURRENT increase last;
//  - the voltage thresholds BUSUNDERV < BUSUNDERVMAX < BRAKEOFFV < BRAKEONV < BUSOVERV keep their order
//    at every step: lowered values are written bottom-up, raised values top-down (e.g. the
//    manual's 360/340 -> 190/170 writes BRAKEOFFV before BRAKEONV);
//  - loop gains that decrease before gains that increase; everything else in profile order.
std::vector<DiffRow> safe_order(std::vector<DiffRow> steps, const params::ParamDb& db);

// Walks the plan's steps from the card's values and names the first state, if any, in which
// a threshold pair is out of order (BRAKEOFFV not below BRAKEONV, BUSUNDERV not below
// BUSOVERV or BUSUNDERVMAX, in either space), as "after writing NVBRAKEONV = 190.00 V: NVBRAKEOFFV 340.00 V
// is not below NVBRAKEONV 190.00 V". Pairs already out of order on the card are not the
// plan's doing and are not reported. An empty result: every step is safe.
std::string unsafe_step(const Plan& plan, const params::ParamDb& db, const RawValues& card);

}  // namespace i20::profile
