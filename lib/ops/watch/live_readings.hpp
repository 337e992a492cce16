// SPDX-License-Identifier: GPL-2.0-or-later
// What a set of live readings (FAULT, STATUS, FAULTMASK, BUSV, ...) says, by the fault
// table's own data (params/faults.yaml): whether the brake is on, whether the fault output
// is on, STATUS explained with the live values (ops::live_values), bit names. For every view of the card: the
// faults report, the watch's events, the passive monitor.
#pragma once

#include <cstdint>
#include <string>

#include "faults/decode.hpp"
#include "faults/report.hpp"
#include "ops/diagnosis.hpp"
#include "ops/faults.hpp"

namespace i20::ops {

// STATUS's brake-on bit (the fault table's "brake-on" slug).
bool brake_on(const FaultReadings& r);
// The fault output (TB1 pins 5-6): on unless a fault FAULTMASK does not mask is set.
bool output_on(const FaultReadings& r);
// STATUS explained with the live readings: BRAKESTATUS while the bus sits above BRAKEONV is
// a warning, not information.
faults::Report live_status_report(const FaultReadings& r);
// "NOENABLEFAULT (bit 1)" or "reserved bit 3".
std::string bit_label(const faults::ReportLine& line);
// The set bits of a register value by name, space-separated: "NOENABLEFAULT BUSUNDERVFAULT".
std::string bit_names(faults::Register reg, std::uint16_t value);

}  // namespace i20::ops
