// SPDX-License-Identifier: GPL-2.0-or-later
#include "device/discover.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <span>
#include <sstream>

#include "lbp/bytes.hpp"
#include "lbp/rpc.hpp"
#include "params/value.hpp"

namespace i20::device {
namespace {

using params::Param;

// SSLBP's per-cycle words, byte by byte: INTERFACE0 write = ANGLE (LSW), QSETPOINT (MSW);
// reads INTERFACE0 = TEMPERATURE (LSW), BUSV (MSW), INTERFACE1 = STATUS (LSW), FAULT (MSW).
constexpr const char* kStreamWords[] = {"ANGLE", "QSETPOINT"};
constexpr const char* kReplyWords[] = {"TEMPERATURE", "BUSV", "STATUS", "FAULT"};

// Address of each byte the RPC takes from the stream / puts in the reply, in order.
struct ByteMap {
  std::vector<std::uint16_t> stream;
  std::vector<std::uint16_t> reply;
};

std::optional<ByteMap> byte_map(const lbp::RpcList& list) {
  ByteMap map;
  for (const auto& step : list.steps) {
    if (!step.address) return std::nullopt;  // pointer-relative steps: cannot place them
    auto& out = step.header.write ? map.stream : map.reply;
    if (step.header.write && step.header.rpc_includes_data) continue;
    for (std::size_t i = 0; i < step.header.data_bytes(); ++i)
      out.push_back(static_cast<std::uint16_t>(*step.address + i));
  }
  return map;
}

// Words must be contiguous, little-endian 16-bit: byte 2k at A, byte 2k+1 at A+1.
std::optional<std::uint16_t> word_address(const std::vector<std::uint16_t>& bytes, std::size_t word) {
  if (bytes.size() < 2 * word + 2 || bytes[2 * word + 1] != bytes[2 * word] + 1) return std::nullopt;
  return bytes[2 * word];
}

}  // namespace

// The RPC that does SSLBP's whole cycle: 4 stream bytes in, 8 reply bytes out.
RpcEvidence decode_rpc_evidence(const lbp::Bytes& table) {
  RpcEvidence evidence;
  auto& note = evidence.note;
  for (unsigned n = 0; n < lbp::kRpcCount && n * lbp::local::kRpcPitch < table.size(); ++n) {
    lbp::RpcList list;
    try {
      list = lbp::decode_rpc_list(table, n);
    } catch (const Error&) {
      continue;
    }
    if (list.stream_bytes != 4 || list.reply_bytes != 8) continue;
    const auto bytes = byte_map(list);
    if (!bytes) continue;
    std::map<std::string, std::uint16_t> found;
    for (std::size_t w = 0; w < 2; ++w)
      if (auto a = word_address(bytes->stream, w)) found[kStreamWords[w]] = *a;
    for (std::size_t w = 0; w < 4; ++w)
      if (auto a = word_address(bytes->reply, w)) found[kReplyWords[w]] = *a;
    note = "RPC " + std::to_string(n) + " (4 bytes in, 8 out: SSLBP's normal-mode cycle)";
    evidence.addresses = std::move(found);
    return evidence;
  }
  note = "no RPC with SSLBP's cycle shape (4 bytes in, 8 out) in the table";
  return evidence;
}

namespace {

bool overlaps(std::uint32_t a, std::size_t a_len, std::uint32_t b, std::size_t b_len) {
  return a < b + b_len && b < a + a_len;
}

std::vector<std::uint16_t> matches(const lbp::Bytes& ram, std::uint32_t base, const lbp::Bytes& value,
                                   unsigned alignment) {
  std::vector<std::uint16_t> out;
  for (std::size_t off = 0; off + value.size() <= ram.size(); ++off) {
    const auto address = base + off;
    if (address % alignment != 0) continue;
    if (std::equal(value.begin(), value.end(), ram.begin() + static_cast<std::ptrdiff_t>(off)))
      out.push_back(static_cast<std::uint16_t>(address));
  }
  return out;
}

lbp::Bytes scan(Amp8i20& amp, const DiscoveryOptions& o) {
  constexpr std::size_t kChunk = 256;  // bytes per exchange: one progress step
  lbp::Bytes ram;
  const std::size_t total = o.scan_end - o.scan_begin;
  for (std::size_t done = 0; done < total; done += kChunk) {
    const auto part = amp.read_memory(params::Space::Ram, static_cast<std::uint16_t>(o.scan_begin + done),
                                      std::min(kChunk, total - done));
    ram.insert(ram.end(), part.begin(), part.end());
    if (o.progress) o.progress(std::min(done + kChunk, total), total);
  }
  return ram;
}

Finding value_finding(const Param& working, const Param& nv, std::int64_t nv_raw, const lbp::Bytes& ram,
                      const DiscoveryOptions& o,
                      const std::vector<std::pair<std::uint16_t, std::size_t>>& taken) {
  Finding f{.name = working.name, .database_address = working.address};
  const auto value = params::bytes_from_raw(working, nv_raw);
  std::vector<std::uint16_t> candidates;
  for (auto a : matches(ram, o.scan_begin, value, o.alignment)) {
    const bool claimed = std::ranges::any_of(
        taken, [&](const auto& t) { return overlaps(a, value.size(), t.first, t.second); });
    if (!claimed) candidates.push_back(a);
  }
  const std::string what = nv.name + " = " + std::to_string(nv_raw);
  if (candidates.size() == 1) {
    f.outcome = Search::Found;
    f.method = Method::UniqueValueMatch;
    f.address = candidates.front();
    f.detail = what + " found once in RAM " + lbp::hex_value(o.scan_begin, 4) + ".." +
               lbp::hex_value(o.scan_end - 1, 4);
  } else if (candidates.empty()) {
    f.detail = what + " not found in RAM " + lbp::hex_value(o.scan_begin, 4) + ".." +
               lbp::hex_value(o.scan_end - 1, 4);
  } else {
    f.outcome = Search::Ambiguous;
    f.candidates = candidates;
    f.detail = what + " found at " + std::to_string(candidates.size()) +
               " places; make the NV value unique (write it, reset) and run discover again";
  }
  return f;
}

// Two working parameters whose NV values are equal (KQP = KDP = 50 by default) hold the same
// bytes after a reset: a scan cannot tell which address is which, even when only one copy
// lies inside the scanned range. Neither is a finding then.
void mark_twins_ambiguous(std::span<Finding> findings, const std::vector<const Param*>& working,
                          const std::vector<Value>& nv_values) {
  for (std::size_t i = 0; i < findings.size(); ++i) {
    std::vector<std::string> equals;
    std::vector<std::uint16_t> candidates;
    for (std::size_t j = 0; j < findings.size(); ++j) {
      if (working[j]->bytes() != working[i]->bytes() || nv_values[j].raw != nv_values[i].raw) continue;
      if (j != i) equals.push_back(working[j]->name);
      if (findings[j].address) candidates.push_back(*findings[j].address);
      candidates.insert(candidates.end(), findings[j].candidates.begin(), findings[j].candidates.end());
    }
    if (equals.empty() || findings[i].outcome == Search::NotFound) continue;
    std::ranges::sort(candidates);
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    auto& f = findings[i];
    std::string others;
    for (const auto& name : equals) others += (others.empty() ? "" : ", ") + name;
    f.outcome = Search::Ambiguous;
    f.method.reset();
    f.address.reset();
    f.candidates = std::move(candidates);
    f.detail = nv_values[i].param->name + " = " + std::to_string(nv_values[i].raw) +
               " equals the NV value of " + others +
               ": the scan cannot tell them apart; make the NV values differ (write one, reset) and run "
               "discover again";
  }
}

}  // namespace

const char* to_string(Search outcome) {
  switch (outcome) {
    case Search::Found: return "found";
    case Search::Ambiguous: return "ambiguous";
    case Search::NotFound: return "not found";
    case Search::NotSearchable: return "not searchable";
  }
  return "?";
}

std::size_t DiscoveryReport::count(Search outcome) const {
  return static_cast<std::size_t>(std::ranges::count(findings, outcome, &Finding::outcome));
}

DiscoveryReport discover(Amp8i20& amp, const DiscoveryOptions& o) {
  auto& db = amp.db();
  DiscoveryReport report;
  report.scan_begin = o.scan_begin;
  report.scan_end = o.scan_end;
  const auto info = amp.info();
  report.swrevision = *info.swrevision;
  report.unit_number = *info.unit_number;

  // 1. The RPC table.
  const auto [from_rpc, rpc_note] = decode_rpc_evidence(amp.read_rpc_table());
  std::vector<std::pair<std::uint16_t, std::size_t>> taken;
  for (const auto* fixed : {"SWREVISION", "UNITNUMBER"})
    taken.emplace_back(*db.get(fixed).address, db.get(fixed).bytes());
  for (const auto& [name, address] : from_rpc) {
    report.findings.push_back({.name = name,
                               .outcome = Search::Found,
                               .method = Method::RpcTable,
                               .address = address,
                               .database_address = db.get(name).address,
                               .detail = "decoded from " + rpc_note});
    taken.emplace_back(address, db.get(name).bytes());
  }

  // 2. Reset, read the NV values, scan RAM for them.
  if (o.reset_first) {
    amp.reset(o.reset_wait);
    report.was_reset = true;
  }
  std::vector<const Param*> nv_params, working;
  for (const auto& p : db.all())
    if (p.is_nv() && p.address && !p.twin.empty()) {
      nv_params.push_back(&p);
      working.push_back(&db.get(p.twin));
    }
  const auto nv_values = amp.read(nv_params);
  const auto ram = scan(amp, o);
  const std::size_t first_value_finding = report.findings.size();
  for (std::size_t i = 0; i < nv_params.size(); ++i)
    report.findings.push_back(value_finding(*working[i], *nv_params[i], nv_values[i].raw, ram, o, taken));
  mark_twins_ambiguous(std::span(report.findings).subspan(first_value_finding), working, nv_values);

  // 3. What neither method can reach without writing.
  for (const auto& p : db.all()) {
    if (p.is_nv() || p.provenance.confirmed_on_all) continue;
    if (std::ranges::find(report.findings, p.name, &Finding::name) != report.findings.end()) continue;
    report.findings.push_back({.name = p.name,
                               .outcome = Search::NotSearchable,
                               .database_address = p.address,
                               .detail = "no NV twin and not in the RPC table: cannot be located read-only"});
  }
  return report;
}

std::string DiscoveryReport::overlay_yaml(const std::string& generated_at) const {
  std::ostringstream y;
  y << "# Working-parameter addresses found by `i20 discover` (read-only discovery).\n"
    << "# Card: unit number " << unit_number << ", SWREVISION " << lbp::hex_value(swrevision, 4) << "; "
    << generated_at << ".\n"
    << "# RAM scanned " << lbp::hex_value(scan_begin, 4) << ".." << lbp::hex_value(scan_end - 1, 4)
    << (was_reset ? " right after a reset" : " WITHOUT a reset (working values may differ from NV)") << ".\n"
    << "# Use with: i20 --params THIS_FILE ...  (applies only to cards reporting this SWREVISION)\n"
    << "schema: 1\nswrevision: " << lbp::hex_value(swrevision, 4) << "\n"
    << "note: \"i20 discover, unit " << unit_number << ", " << generated_at << "\"\nparameters:\n";
  for (const auto& f : findings) {
    if (f.outcome != Search::Found) continue;
    const char* how = f.method == Method::RpcTable ? "RPC table decode" : "unique NV value match after reset";
    y << "  - name: " << f.name << "\n    address: " << lbp::hex_value(*f.address, 4) << "\n"
      << "    provenance: {source: \"i20 discover (" << how << ") on unit " << unit_number << ", "
      << generated_at << "\", confirmed_on: [" << lbp::hex_value(swrevision, 4) << "]}\n";
  }
  // The database's guesses for what was not found are wrong on this card as often as
  // not, and could collide with what was: on this revision their address is unknown.
  for (const auto& f : findings) {
    if (f.outcome == Search::Found) continue;
    y << "  - name: " << f.name << "\n    address: null\n"
      << "    provenance: {source: \"i20 discover on unit " << unit_number << ": " << to_string(f.outcome)
      << "\", confirmed_on: []}\n";
  }
  for (const auto& f : findings) {
    if (f.outcome == Search::Found) continue;
    y << "# " << f.name << ": " << to_string(f.outcome) << ": " << f.detail;
    if (!f.candidates.empty()) {
      y << " (candidates:";
      for (auto c : f.candidates) y << " " << lbp::hex_value(c, 4);
      y << ")";
    }
    y << "\n";
  }
  return y.str();
}

}  // namespace i20::device
