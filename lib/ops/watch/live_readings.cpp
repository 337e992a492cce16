// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/watch/live_readings.hpp"

#include "faults/fault_mask.hpp"
#include "faults/fault_table.hpp"

namespace i20::ops {

namespace F = i20::faults;

bool brake_on(const FaultReadings& r) {
  // Which bit that is, is the knowledge base's (params/faults.yaml, slug brake-on).
  static const F::BitInfo* const brake = F::FaultTable::builtin().find(F::Register::Status, "brake-on");
  return brake && (r.status & brake->mask()) != 0;
}

bool output_on(const FaultReadings& r) {
  return F::mask_state(r.fault, r.faultmask.value_or(F::kNothingMasked)).fault_output_on();
}

F::Report live_status_report(const FaultReadings& r) {
  return F::status_report(r.status, live_values(r));
}

std::string bit_label(const F::ReportLine& line) {
  if (line.reserved) return "reserved bit " + std::to_string(line.bit);
  return line.name + " (bit " + std::to_string(line.bit) + ")";
}

std::string bit_names(F::Register reg, std::uint16_t value) {
  std::string out;
  for (const auto& b : F::decode(reg, value).bits) {
    if (!out.empty()) out += ' ';
    out += b.label();  // appended: GCC 12's -O3 takes `"" + std::string&&` for an overlapping copy
  }
  return out;
}

}  // namespace i20::ops
