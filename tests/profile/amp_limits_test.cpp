// SPDX-License-Identifier: GPL-2.0-or-later
// The card's own limits (profile/amp_limits.hpp) against the manual, and against the data
// that states them too.
#include "profile/amp_limits.hpp"

#include <gtest/gtest.h>

#include "params/param_db.hpp"

using namespace i20::profile;

// Manual, FAULT CONDITIONS: MAXBUSVFAULT, fixed at 400 V; MOTOR POWER: 35 to 400 VDC. Held
// by the fault table, which the diagnosis of that fault reads.
TEST(AmpLimits, BusLimitIsTheFaultTables400V) {
  EXPECT_DOUBLE_EQ(amp_max_bus_v(), 400.0);
  EXPECT_EQ(limit_text(amp_max_bus_v(), "V"), "400 V");
}

// Manual, MAXCURRENT and SPECIFICATIONS: 30 A RMS. The shipped database's MAXCURRENT and
// NVMAXCURRENT ranges end there too (an overlay may widen them; the constant still holds).
TEST(AmpLimits, CurrentLimitIs30AAndTheDatabaseRangesAgree) {
  EXPECT_DOUBLE_EQ(kAmpMaxCurrentA, 30.0);
  EXPECT_EQ(limit_text(kAmpMaxCurrentA, "A"), "30 A");
  const auto db = i20::params::ParamDb::builtin();
  for (const char* name : {"MAXCURRENT", "NVMAXCURRENT"}) {
    const auto& p = db.get(name);
    EXPECT_NEAR(static_cast<double>(p.max) * p.scale, kAmpMaxCurrentA, 1e-9) << name;
  }
}
