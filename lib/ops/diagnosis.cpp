// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/diagnosis.hpp"

#include <cstdio>
#include <utility>

namespace i20::ops {
namespace {

using faults::LiveCheck;

std::string reading(double value, const std::string& unit) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.2f", value);
  return std::string(buf) + " " + unit;
}

// "the 85 degC limit", "the fixed 400 V limit".
std::string limit(double value, const LiveCheck& c) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%g", value);
  return std::string("the ") + (c.fixed ? "fixed " : "") + buf + " " + c.unit + " limit";
}

// The measurement against its threshold; Unknown when either is not known.
CauseNow measured_cause(const LiveCheck& c, const faults::LiveValues& live) {
  const auto measured = live.find(c.measured);
  if (measured == live.end()) return {};
  double threshold = 0;
  std::string threshold_text;
  if (c.threshold_value) {
    threshold = *c.threshold_value;
    threshold_text = limit(threshold, c);
  } else {
    const auto it = live.find(c.threshold_param);
    if (it == live.end()) return {};
    threshold = it->second;
    threshold_text = c.threshold_param + " " + reading(threshold, c.unit);
  }
  const double v = measured->second;
  const bool above = c.compare == LiveCheck::Compare::Above;
  const bool present = above ? v > threshold : v < threshold;
  const std::string head = c.measured + " is " + reading(v, c.unit) + ", ";
  if (present)
    return {CauseNow::Present, head + (above ? "above " : "below ") + threshold_text +
                                   (c.advice.empty() ? "" : ": " + c.advice)};
  return {CauseNow::Gone, head + (above ? "below " : "above ") + threshold_text};
}

CauseNow status_cause(const LiveCheck& c, std::uint16_t status) {
  const std::string bit = "STATUS bit " + std::to_string(*c.status_bit);
  if (status & (1u << *c.status_bit)) return {CauseNow::Present, c.status_set + " (" + bit + ")"};
  if (!c.status_clear.empty()) return {CauseNow::Gone, c.status_clear + " (" + bit + " clear)"};
  return {};
}

}  // namespace

faults::LiveValues live_values(const FaultReadings& r) {
  faults::LiveValues live;
  const std::pair<const char*, const std::optional<double>*> all[] = {{"BUSV", &r.busv_v},
                                                                      {"TEMPERATURE", &r.temperature_c},
                                                                      {"BUSUNDERV", &r.busunderv_v},
                                                                      {"BUSOVERV", &r.busoverv_v},
                                                                      {"BRAKEONV", &r.brakeonv_v}};
  for (const auto& [name, value] : all)
    if (*value) live[name] = **value;
  return live;
}

CauseNow cause_now(unsigned fault_bit, const FaultReadings& r, const faults::FaultTable& table) {
  const faults::BitInfo* bit = table.find(faults::Register::Fault, fault_bit);
  if (!bit || !bit->live_check) return {};
  const LiveCheck& c = *bit->live_check;
  if (!c.measured.empty())
    if (CauseNow m = measured_cause(c, live_values(r)); m.state != CauseNow::Unknown) return m;
  if (c.status_bit) return status_cause(c, r.status);
  return {};
}

}  // namespace i20::ops
