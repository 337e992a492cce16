// SPDX-License-Identifier: GPL-2.0-or-later
// Finding the working (RAM) addresses of a real 8I20 without writing to it (issue 4;
// docs/facts.md s3 names both methods):
//  1. the pre-loaded RPC table holds the commands SSLBP's normal mode runs every cycle
//     (write ANGLE and QSETPOINT, read TEMPERATURE, BUSV, STATUS, FAULT, in the order of
//     SSLBP's INTERFACE0/INTERFACE1 words, LSW first), so decoding it names those
//     addresses;
//  2. right after a reset every working parameter equals its NV twin, so a read-only
//     scan of RAM for each NV value locates candidates. A value found at exactly one
//     place is taken; a value found at several (KQP = KDP = 50 by default) cannot be
//     told apart without writing, and is reported as ambiguous with its candidates.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "device/amp.hpp"
#include "link/given.hpp"

namespace i20::device {

struct DiscoveryOptions {
  // RAM scanned for working twins. The default skips 0x0000-0x07FF, where a DSP keeps
  // its special-function registers and a read may have side effects (e.g. pop a UART
  // byte); SWREVISION (2164) and UNITNUMBER (2344) sit above it. An assumption, not a
  // published fact: widen it with care.
  std::uint16_t scan_begin = 0x0800;
  std::uint32_t scan_end = 0x2800;  // exclusive
  bool reset_first = true;          // working == NV only right after a reset
  // How long the card may take to answer again after that reset (ops/core/timing.hpp).
  link::Given<std::chrono::milliseconds> reset_wait;
  unsigned alignment = 2;           // 16/32-bit parameters start at even addresses
  std::function<void(std::size_t done, std::size_t total)> progress{};
};

enum class Method { RpcTable, UniqueValueMatch };
// What the search for one parameter's working address found.
enum class Search { Found, Ambiguous, NotFound, NotSearchable };

struct Finding {
  std::string name;
  Search outcome = Search::NotFound;
  std::optional<Method> method{};
  std::optional<std::uint16_t> address{};           // when Found
  std::vector<std::uint16_t> candidates{};          // when Ambiguous
  std::optional<std::uint16_t> database_address{};  // what the database says, for comparison
  std::string detail{};                             // one line: why, for the report and the file
};

struct DiscoveryReport {
  std::uint16_t swrevision = 0;
  std::uint32_t unit_number = 0;
  bool was_reset = false;
  std::uint16_t scan_begin = 0;
  std::uint32_t scan_end = 0;
  std::vector<Finding> findings;

  std::size_t count(Search outcome) const;
  // The overlay file for `i20 --params`: found addresses confirmed for this revision,
  // the rest as comments.
  std::string overlay_yaml(const std::string& generated_at) const;
};

// Addresses the card's pre-loaded RPC table names: the RPC with SSLBP's normal-mode cycle
// shape (4 stream bytes in: ANGLE, QSETPOINT; 8 reply bytes out: TEMPERATURE, BUSV, STATUS,
// FAULT). Pure: decodes a table already read. `note` says which RPC, or why none.
struct RpcEvidence {
  std::map<std::string, std::uint16_t> addresses;
  std::string note;
};
RpcEvidence decode_rpc_evidence(const lbp::Bytes& table);

// Runs discovery on the connected card. Sends only reads, local commands, the RPC
// memory access flag (always cleared again) and, when reset_first, the 0xFE 0x5A reset.
DiscoveryReport discover(Amp8i20& amp, const DiscoveryOptions& options);

const char* to_string(Search outcome);

}  // namespace i20::device
