// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/report.hpp"

#include <algorithm>

#include "link/pipelined_link.hpp"
#include "profile/save.hpp"
#include "profile/timestamp.hpp"

namespace i20::ops {

ServiceReport gather_report(Card& card, std::chrono::system_clock::time_point when) {
  ServiceReport r;
  r.when = when;
  r.target = card.endpoint().text;
  r.identity = card.identity();
  r.values = read_all(card);
  for (const auto& v : r.values) {
    const auto& p = *v.param;
    if (!p.is_nv() || p.twin.empty() || !v.fact()) continue;
    const auto twin =
        std::find_if(r.values.begin(), r.values.end(), [&](const Reading& w) { return w.param->name == p.twin; });
    if (twin != r.values.end() && twin->fact() && *twin->raw != *v.raw) r.not_live.push_back(p.name);
  }
  try {
    r.faults = read_fault_registers(card);
  } catch (const Error& e) {
    if (e.kind() == ErrorKind::Cancelled) throw;
    r.faults_error = e.what();
  }
  if (const auto* pipelined = dynamic_cast<const link::PipelinedLink*>(&card.link())) {
    const auto& s = pipelined->statistics();
    r.link = LinkFigures{s.exchanges, s.commands, s.bytes_sent, s.bytes_received,
                         s.timeouts,  s.crc_errors, s.framing_errors, s.resyncs};
  }
  r.retries = card.retries();
  r.link_notes = card.link().notes();
  return r;
}

profile::Profile report_profile(const ServiceReport& report, const params::ParamDb& db) {
  profile::RawValues values;
  std::vector<std::string> names;
  for (const auto& name : profile::default_save_names(db))
    for (const auto& v : report.values)
      if (v.param->name == name && v.fact()) {
        values[name] = *v.raw;
        names.push_back(name);
      }
  profile::SaveOptions options;
  options.name = "report-unit" + lbp::hex_value(report.identity.info.unit_number.value_or(0), 8).substr(2);
  options.notes = "The NV setup `i20 report` read from this card; apply this file to write it back.";
  options.when = report.when;
  return profile::profile_from_values(values, names, db, report.target, options);
}

}  // namespace i20::ops
