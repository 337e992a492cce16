// The 8I20 as the rest of the toolkit sees it: parameters by name, read and written
// under the safety rules, over any Link.
//
// Safety rules enforced here, not only in the apps (issue 4):
//  - a value outside the database's range is refused before anything is sent;
//  - writing an address the database does not confirm for this card's firmware is
//    refused unless WriteOptions::allow_unverified;
//  - guarded parameters (NVBAUDRATE, setpoints) need WriteOptions::force;
//  - NV writes enter NV access mode, write, read back and compare, and leave NV mode on
//    every path (ModeGuard), also on error and when cancelled (Ctrl-C).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "link/link.hpp"
#include "params/param_db.hpp"

namespace i20::device {

struct CardInfo {
  std::string card_name;  // "8I20"
  lbp::Byte unit_address = 0;
  lbp::Byte unit_id = 0;
  lbp::Byte lbp_version = 0;
  lbp::Byte lbp_status = 0;
  lbp::Byte crc_errors = 0;
  lbp::Byte rpc_pitch = 0;
  std::uint16_t rpc_size = 0;
  std::optional<std::uint16_t> swrevision;
  std::optional<std::uint32_t> unit_number;
  bool working_map_confirmed = false;  // the database's RAM map is confirmed for this revision
};

struct Value {
  const params::Param* param = nullptr;
  std::int64_t raw = 0;
  bool address_confirmed = false;
};

struct WriteOptions {
  bool allow_unverified = false;  // write RAM addresses the database does not confirm
  bool force = false;             // write guarded parameters (NVBAUDRATE, setpoints)
};

struct Assignment {
  const params::Param* param = nullptr;
  std::int64_t raw = 0;
};

struct WriteReport {
  const params::Param* param = nullptr;
  std::int64_t raw = 0;
  bool verified = false;     // read back equal (false only for self-clearing registers)
  bool needs_reset = false;  // NV value: takes effect after the 8I20 is reset
};

struct ClearFaultsResult {
  std::uint16_t fault_before = 0;
  std::uint16_t fault_after = 0;
  std::uint16_t status_after = 0;
  std::chrono::milliseconds took{0};
};

// The rules that need no card: writable, address known, range, guard. Apps call it
// before they even open the link, so a refused value sends nothing at all.
void check_offline(const params::Param& param, std::int64_t raw, const WriteOptions& options);

class Amp8i20 {
 public:
  // `cancel`, when given, is polled between exchanges (set it from a SIGINT handler).
  Amp8i20(link::Link& link, params::ParamDb& db, const std::atomic<bool>* cancel = nullptr);

  // Reads SWREVISION and selects the database's map for it. Returns the revision. Reads
  // and checked writes identify the card by themselves when this was not called.
  std::uint16_t identify();
  CardInfo info();

  Value read(std::string_view name);
  // One pipelined exchange: RAM reads, then NV reads inside NV access mode.
  std::vector<Value> read(std::span<const params::Param* const> params);

  // Throws SafetyError if the rules refuse this write (check_offline, then whether the
  // address is confirmed for this card's firmware). Sends nothing.
  void check_write(const params::Param& param, std::int64_t raw, const WriteOptions& options);
  WriteReport write(std::string_view name, std::int64_t raw, const WriteOptions& options);
  // Checks every assignment before the first byte is sent, then writes in order.
  std::vector<WriteReport> write(std::span<const Assignment> assignments, const WriteOptions& options);

  // 0xFE 0x5A, then waits until the card answers again (NV values become live).
  void reset(std::chrono::milliseconds wait = std::chrono::milliseconds(3000));

  // Sets CLEARFAULT, polls until the card clears it (deadline), re-reads FAULT/STATUS.
  ClearFaultsResult clear_faults(const WriteOptions& options,
                                 std::chrono::milliseconds deadline = std::chrono::milliseconds(1000));

  // Raw reads for discovery and diagnostics (read-only, any address).
  lbp::Bytes read_memory(params::Space space, std::uint16_t address, std::size_t count);
  // The RPC table (RPCMEM access enabled only for the read, always disabled after).
  lbp::Bytes read_rpc_table();

  link::Link& link() { return link_; }
  params::ParamDb& db() { return db_; }

 private:
  void throw_if_cancelled() const;
  std::vector<WriteReport> write_ram(std::span<const Assignment> batch);
  std::vector<WriteReport> write_nv(std::span<const Assignment> batch);

  link::Link& link_;
  params::ParamDb& db_;
  const std::atomic<bool>* cancel_;
};

}  // namespace i20::device
