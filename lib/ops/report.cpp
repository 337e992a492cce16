// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/report.hpp"

#include <algorithm>

#include "link/pipelined_link.hpp"
#include "ops/reset.hpp"
#include "profile/save.hpp"
#include "profile/timestamp.hpp"

namespace i20::ops {

ServiceReport gather_report(Amp& amp, std::chrono::system_clock::time_point when) {
  ServiceReport r;
  r.when = when;
  r.target = amp.endpoint().text;
  r.identity = amp.identity();
  r.values = read_all(amp);
  profile::RawValues facts;
  for (const auto& v : r.values)
    if (v.fact()) facts[v.param->name] = *v.raw;
  r.not_live = pending_nv_values(amp.db(), facts);
  try {
    r.faults = read_fault_registers(amp);
  } catch (const Error& e) {
    if (e.kind() == ErrorKind::Cancelled) throw;
    r.faults_error = e.what();
  }
  if (const auto* pipelined = dynamic_cast<const link::PipelinedLink*>(&amp.link())) {
    const auto& s = pipelined->statistics();
    r.link = LinkFigures{s.exchanges, s.commands,   s.bytes_sent,     s.bytes_received,
                         s.timeouts,  s.crc_errors, s.framing_errors, s.resyncs};
  }
  r.retries = amp.retries();
  r.link_notes = amp.link().notes();
  return r;
}

profile::Profile report_profile(const ServiceReport& report, const params::ParamDb& db) {
  profile::RawValues values;
  for (const auto& v : report.values)
    if (v.fact()) values[v.param->name] = *v.raw;
  const std::vector<std::string> names = profile::names_to_save(db, values);
  profile::SaveOptions options;
  options.name = "report-unit" + lbp::hex_value(report.identity.info.unit_number.value_or(0), 8).substr(2);
  options.notes = "The NV setup `i20 report` read from this card; apply this file to write it back.";
  options.when = report.when;
  return profile::profile_from_values(values, names, db, report.target, options);
}

}  // namespace i20::ops
