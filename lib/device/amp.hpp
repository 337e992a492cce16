// SPDX-License-Identifier: GPL-2.0-or-later
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

#include "lbp/local.hpp"
#include "link/given.hpp"
#include "link/link.hpp"
#include "params/param_db.hpp"

namespace i20::device {

struct AmpInfo {
  std::string card_name;                                       // "8I20"
  lbp::local::NvAccess nv_access = lbp::local::NvAccess::Ram;  // as found (0xCC)
  bool rpcmem = false;                                         // RPC memory access as found (0xCA)
  lbp::Byte unit_address = 0;
  lbp::Byte unit_id = 0;
  lbp::Byte lbp_version = 0;
  lbp::Byte lbp_status = 0;
  lbp::Byte crc_errors = 0;
  lbp::Byte rpc_pitch = 0;
  std::uint16_t rpc_size = 0;
  std::optional<std::uint16_t> swrevision;
  std::optional<std::uint32_t> unit_number;
  // Every writable working parameter's address is confirmed for this revision (judged by
  // the database the client was given: resolve it for the card first).
  bool working_map_confirmed = false;
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

// Every writable working parameter's address is confirmed in this (resolved) database.
bool working_map_confirmed(const params::ParamDb& db);

// The rules that need no card: writable, address known, range, guard. Apps call it
// before they even open the link, so a refused value sends nothing at all.
void check_offline(const params::Param& param, std::int64_t raw, const WriteOptions& options);

// The card reset while an EEPROM cell was being written: NV access mode was gone when the
// card was asked right after the cell. The write may have reached the EEPROM, nowhere (the
// card was deaf), or working memory at the EEPROM address (the card was already back in
// normal access mode). `stray_ram_value` says whether working memory at that address now
// holds exactly the value written (strong evidence of the last case).
class NvModeLost : public Error {
 public:
  NvModeLost(const std::string& message, std::string cell, std::uint16_t address, bool stray_ram_value)
      : Error(message, ErrorKind::Uncertain),
        cell_(std::move(cell)),
        address_(address),
        stray_ram_value_(stray_ram_value) {}
  const std::string& cell() const { return cell_; }
  std::uint16_t address() const { return address_; }
  bool stray_ram_value() const { return stray_ram_value_; }

 private:
  std::string cell_;
  std::uint16_t address_;
  bool stray_ram_value_;
};

// The client's own tries and pauses, given by its owner (ops/core/timing.hpp sets the programs').
struct AmpTiming {
  // Sends of the batch that leaves NV access or RPC memory mode before the mode is reported
  // as possibly still on (the first may fail right after the error that brought us there).
  link::Given<unsigned> leave_mode_tries;
  // Pauses between polls: of the cookie after a reset, and of CLEARFAULT after writing it.
  link::Given<std::chrono::milliseconds> reset_poll;
  link::Given<std::chrono::milliseconds> clear_fault_poll;
};

class Amp8i20 {
 public:
  // `db` is the database resolved for this card (ParamDb::for_firmware, plus the card's own
  // evidence); the client never changes it. `cancel`, when given, is polled between
  // exchanges (set it from a SIGINT handler).
  Amp8i20(link::Link& link, const params::ParamDb& db, AmpTiming timing,
          const std::atomic<bool>* cancel = nullptr);

  // Reads SWREVISION (a public address on every firmware).
  std::uint16_t identify();
  // Name, unit, firmware, LBP state and the two modes (NV access, RPC memory) in one exchange.
  AmpInfo info();
  // Takes the card out of NV access and RPC memory access mode and confirms it (a previous
  // session may have died inside them). Returns what was switched off, for messages.
  std::vector<std::string> leave_modes();

  Value read(std::string_view name);
  // One pipelined exchange: RAM reads, then NV reads inside NV access mode.
  std::vector<Value> read(std::span<const params::Param* const> params);

  // Throws SafetyError if the rules refuse this write (check_offline, then whether the
  // address is confirmed for this card's firmware). Sends nothing.
  void check_write(const params::Param& param, std::int64_t raw, const WriteOptions& options);
  WriteReport write(std::string_view name, std::int64_t raw, const WriteOptions& options);
  // Checks every assignment before the first byte is sent, then writes: RAM cells (each
  // written and read back), then EEPROM cells in one NV session. An EEPROM data write is
  // sent only after the card has confirmed NV access mode in a reply, and the mode is
  // confirmed again after each cell (NvModeLost when it is gone).
  std::vector<WriteReport> write(std::span<const Assignment> assignments, const WriteOptions& options);

  // 0xFE 0x5A, then waits up to `wait` until the card answers again (NV values become
  // live). The wait is the caller's (ops/core/timing.hpp).
  void reset(std::chrono::milliseconds wait);

  // Sets CLEARFAULT, polls until the card clears it (up to `deadline`, the caller's),
  // re-reads FAULT/STATUS.
  ClearFaultsResult clear_faults(const WriteOptions& options, std::chrono::milliseconds deadline);

  // Raw reads for discovery and diagnostics (read-only, any address).
  lbp::Bytes read_memory(params::Space space, std::uint16_t address, std::size_t count);
  // The RPC table (RPCMEM access enabled only for the read, always disabled after).
  lbp::Bytes read_rpc_table();
  // `count` bytes of it from `offset`, the same way (a client that needs one RPC reads no more).
  lbp::Bytes read_rpc_table(std::size_t offset, std::size_t count);

  link::Link& link() { return link_; }
  const params::ParamDb& db() const { return db_; }
  void set_cancel(const std::atomic<bool>* cancel) { cancel_ = cancel; }
  // A mode (NV access, RPC memory access) the card may still be in because leaving it
  // failed when the line died; "" when none. leave_modes() settles it.
  const std::string& unsettled_mode() const { return unsettled_mode_; }

 private:
  void throw_if_cancelled() const;
  std::vector<WriteReport> write_ram(std::span<const Assignment> batch);
  std::vector<WriteReport> write_nv(std::span<const Assignment> batch);
  void check_nv_cell(const Assignment& a, const std::vector<lbp::Bytes>& replies);

  link::Link& link_;
  const params::ParamDb& db_;
  AmpTiming timing_;
  const std::atomic<bool>* cancel_;
  std::string unsettled_mode_;
};

}  // namespace i20::device
