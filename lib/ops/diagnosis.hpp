// SPDX-License-Identifier: GPL-2.0-or-later
// Whether a latched FAULT bit's cause is there now, judged from one pass of live readings
// by the bit's `live_check` in the fault table (params/faults.yaml): which reading or STATUS
// bit shows the condition, and its threshold. The facts are the table's; this only applies them.
#pragma once

#include <string>

#include "faults/fault_table.hpp"
#include "faults/report.hpp"
#include "ops/faults.hpp"

namespace i20::ops {

// What the live readings say about a FAULT bit's cause right now.
struct CauseNow {
  enum State { Present, Gone, Unknown };
  State state = Unknown;
  std::string evidence;  // "BUSV is 24.00 V, below BUSUNDERV 35.00 V"; empty when Unknown
};

// Unknown for reserved bits, bits without a live check (hardware events: only the card can
// tell) and readings that do not decide it (a value or threshold not read).
CauseNow cause_now(unsigned fault_bit, const FaultReadings& r,
                   const faults::FaultTable& table = faults::FaultTable::builtin());

// The readings by parameter name (BUSV, TEMPERATURE, BUSUNDERV, BUSOVERV, BRAKEONV), in
// engineering units; readings not taken are missing.
faults::LiveValues live_values(const FaultReadings& r);

}  // namespace i20::ops
