// SPDX-License-Identifier: GPL-2.0-or-later
#include "device/amp.hpp"

#include <algorithm>
#include <thread>

#include "device/errors.hpp"
#include "device/mode_guard.hpp"
#include "lbp/bytes.hpp"
#include "lbp/local.hpp"
#include "params/value.hpp"

namespace i20::device {
namespace {

using params::Param;
using params::Space;
using Clock = std::chrono::steady_clock;

lbp::DataSize size_of(const Param& p) {
  return *lbp::data_size_for(p.bytes());
}

std::uint16_t address_of(const Param& p) {
  if (!p.address)
    throw SafetyError("the address of " + p.name + " is not known (" + p.provenance.source +
                      "); give it in an overlay file with --params");
  return *p.address;
}

lbp::Command read_command(const Param& p) {
  return lbp::read(address_of(p), size_of(p));
}

lbp::Command write_command(const Param& p, std::int64_t raw) {
  auto c = lbp::write(address_of(p), size_of(p), static_cast<std::uint64_t>(raw));
  // An EEPROM cell write takes milliseconds: nothing may follow until it is answered.
  c.barrier = p.is_nv();
  return c;
}

// Reads of `count` bytes from `address` in as few commands as the header and the
// transport allow (`largest` = 8 on a serial line, 4 through SSLBP).
std::vector<lbp::Command> chunked_reads(std::uint16_t address, std::size_t count, std::size_t largest) {
  std::vector<lbp::Command> commands;
  for (std::size_t done = 0; done < count;) {
    const std::size_t left = std::min(count - done, largest);
    const std::size_t chunk = left >= 8 ? 8 : left >= 4 ? 4 : left >= 2 ? 2 : 1;
    commands.push_back(lbp::read(static_cast<std::uint16_t>(address + done), *lbp::data_size_for(chunk)));
    done += chunk;
  }
  return commands;
}

// The card's answer to 0xCC must be EEPROM access, or it did not enter the mode (or reset).
void require_nv_mode(const lbp::Bytes& reply, const std::string& what) {
  if (reply.at(0) != static_cast<lbp::Byte>(lbp::local::NvAccess::Eeprom))
    throw Error("the 8I20 did not confirm NV access mode " + what +
                ": nothing was written to the EEPROM; check its logic power and run the command again");
}

void verify(const Param& p, std::int64_t wanted, lbp::ByteView readback) {
  const auto got = params::raw_from_bytes(p, readback);
  if (got != wanted)
    throw VerifyError(p.name + ": wrote " + std::to_string(wanted) + " but the card reads back " +
                      std::to_string(got) + (p.is_nv() ? " (EEPROM write failed?)" : ""));
}

}  // namespace

Amp8i20::Amp8i20(link::Link& link, const params::ParamDb& db, AmpTiming timing,
                 const std::atomic<bool>* cancel)
    : link_(link), db_(db), timing_(timing), cancel_(cancel) {}

void Amp8i20::throw_if_cancelled() const {
  if (cancel_ && cancel_->load())
    throw Cancelled("interrupted; the 8I20 was left in normal (RAM) access mode");
}

std::uint16_t Amp8i20::identify() {
  const auto& revision = db_.get("SWREVISION");
  return static_cast<std::uint16_t>(
      params::raw_from_bytes(revision, link_.execute_one(read_command(revision))));
}

bool working_map_confirmed(const params::ParamDb& db) {
  bool any = false;
  for (const auto& p : db.all()) {
    if (p.is_nv() || !p.writable() || !p.address) continue;
    if (!db.address_confirmed(p)) return false;
    any = true;
  }
  return any;
}

AmpInfo Amp8i20::info() {
  namespace L = lbp::local;
  const std::vector<lbp::Command> batch{
      lbp::local_read(L::kGetCardName0),     lbp::local_read(L::kGetCardName0 + 1),
      lbp::local_read(L::kGetCardName0 + 2), lbp::local_read(L::kGetCardName3),
      lbp::local_read(L::kGetUnitAddress),   lbp::local_read(L::kGetUnitId),
      lbp::local_read(L::kGetLbpVersion),    lbp::local_read(L::kGetStatus),
      lbp::local_read(L::kGetCrcErrorCount), lbp::local_read(L::kGetRpcPitch),
      lbp::local_read(L::kGetRpcSizeLow),    lbp::local_read(L::kGetRpcSizeHigh),
      read_command(db_.get("SWREVISION")),   read_command(db_.get("UNITNUMBER")),
      lbp::local_read(L::kGetNvAccess),      lbp::local_read(L::kGetRpcMemAccess),
  };
  const auto r = link_.execute(batch);
  AmpInfo info;
  for (int i = 0; i < 4; ++i) info.card_name.push_back(static_cast<char>(r[i].at(0)));
  info.unit_address = r[4].at(0);
  info.unit_id = r[5].at(0);
  info.lbp_version = r[6].at(0);
  info.lbp_status = r[7].at(0);
  info.crc_errors = r[8].at(0);
  info.rpc_pitch = r[9].at(0);
  info.rpc_size = static_cast<std::uint16_t>(r[10].at(0) | (r[11].at(0) << 8));
  info.swrevision = static_cast<std::uint16_t>(lbp::read_le(r[12]));
  info.unit_number = static_cast<std::uint32_t>(lbp::read_le(r[13]));
  info.nv_access = static_cast<L::NvAccess>(r[14].at(0));
  info.rpcmem = r[15].at(0) != 0;
  info.working_map_confirmed = working_map_confirmed(db_);
  return info;
}

std::vector<std::string> Amp8i20::leave_modes() {
  namespace L = lbp::local;
  const std::vector<lbp::Command> batch{
      lbp::local_read(L::kGetNvAccess),     lbp::local_read(L::kGetRpcMemAccess),
      lbp::set_nv_access(L::NvAccess::Ram), lbp::local_write(L::kSetRpcMemAccess, 0),
      lbp::local_read(L::kGetNvAccess),     lbp::local_read(L::kGetRpcMemAccess)};
  const auto r = link_.execute(batch);
  unsettled_mode_.clear();  // confirmed below, or thrown
  std::vector<std::string> left;
  if (r[0].at(0) != static_cast<lbp::Byte>(L::NvAccess::Ram)) left.push_back("NV access mode");
  if (r[1].at(0) != 0) left.push_back("RPC memory access");
  if (r[4].at(0) != static_cast<lbp::Byte>(L::NvAccess::Ram) || r[5].at(0) != 0)
    throw AmpStateError("the 8I20 on " + link_.describe() +
                        " stays in NV or RPC memory access mode after being told to leave it: reset it "
                        "(i20 reset) or cycle its logic power");
  return left;
}

Value Amp8i20::read(std::string_view name) {
  const Param* p = &db_.get(name);
  return read(std::span<const Param* const>(&p, 1)).front();
}

std::vector<Value> Amp8i20::read(std::span<const Param* const> params) {
  throw_if_cancelled();
  // One exchange for everything: every exchange costs a reply turnaround, which on a USB
  // adapter is a latency-timer tick. Order: SWREVISION (when the card is not identified
  // yet), the RAM reads, then the NV reads between entering and leaving NV mode.
  std::vector<lbp::Command> commands;
  std::vector<std::size_t> reply_of(params.size());
  for (std::size_t i = 0; i < params.size(); ++i)
    if (!params[i]->is_nv()) {
      reply_of[i] = commands.size();
      commands.push_back(read_command(*params[i]));
    }
  const auto leave = lbp::set_nv_access(lbp::local::NvAccess::Ram);
  const auto nv_mode = lbp::local_read(lbp::local::kGetNvAccess);
  const bool any_nv = std::ranges::any_of(params, &Param::is_nv);
  if (any_nv) {
    commands.push_back(lbp::set_nv_access(lbp::local::NvAccess::Eeprom));
    for (std::size_t i = 0; i < params.size(); ++i)
      if (params[i]->is_nv()) {
        reply_of[i] = commands.size();
        commands.push_back(read_command(*params[i]));
      }
    // As for writes: if the card reset inside the batch, the NV reads came from RAM.
    commands.push_back(nv_mode);
    commands.push_back(leave);
    commands.push_back(nv_mode);  // the reply that proves it left
  }

  std::optional<ModeGuard> guard;
  if (any_nv)
    guard.emplace(link_, leave, nv_mode, "NV (EEPROM) access mode", timing_.leave_mode_tries,
                  &unsettled_mode_);
  const auto replies = link_.execute(commands);
  if (guard) {
    guard->disarm(replies.back());
    if (replies[replies.size() - 3].at(0) != static_cast<lbp::Byte>(lbp::local::NvAccess::Eeprom))
      throw AmpStateError(
          "the 8I20 on " + link_.describe() +
          " left NV access mode during the read (it reset?): NV values not shown; read again");
  }

  std::vector<Value> out;
  for (std::size_t i = 0; i < params.size(); ++i)
    out.push_back({params[i], params::raw_from_bytes(*params[i], replies[reply_of[i]]),
                   db_.address_confirmed(*params[i])});
  return out;
}

void check_offline(const Param& p, std::int64_t raw, const WriteOptions& options) {
  if (!p.writable()) {
    const std::string hint = p.name == "FAULT" ? ": faults clear through CLEARFAULT (i20 clear-faults)" : "";
    throw SafetyError(p.name + " is read-only" + hint);
  }
  address_of(p);
  try {
    params::check_range(p, raw);
  } catch (const params::ValueError& e) {
    throw SafetyError(std::string(e.what()) + "; nothing was written");
  }
  if (!p.guard.empty() && !options.force)
    throw SafetyError("refusing to write " + p.name + ", a guarded parameter: " + p.guard, Advice::Force);
}

void Amp8i20::check_write(const Param& p, std::int64_t raw, const WriteOptions& options) {
  check_offline(p, raw, options);
  if (!options.allow_unverified && !db_.address_confirmed(p)) {
    const auto rev = db_.firmware();
    throw SafetyError("refusing to write " + p.name +
                          ": its address is not confirmed for this 8I20's firmware" +
                          (rev ? " (SWREVISION " + lbp::hex_value(*rev, 4) + ")" : std::string()) + " [" +
                          p.provenance.source + "]; run `i20 discover`",
                      Advice::AllowUnverified);
  }
}

WriteReport Amp8i20::write(std::string_view name, std::int64_t raw, const WriteOptions& options) {
  const Assignment a{&db_.get(name), raw};
  return write(std::span<const Assignment>(&a, 1), options).front();
}

std::vector<WriteReport> Amp8i20::write(std::span<const Assignment> assignments,
                                        const WriteOptions& options) {
  throw_if_cancelled();
  for (const auto& a : assignments) check_write(*a.param, a.raw, options);
  std::vector<Assignment> ram, nv;
  for (const auto& a : assignments) (a.param->is_nv() ? nv : ram).push_back(a);
  throw_if_cancelled();
  auto reports = write_ram(ram);
  throw_if_cancelled();
  auto nv_reports = write_nv(nv);
  reports.insert(reports.end(), nv_reports.begin(), nv_reports.end());
  return reports;
}

std::vector<WriteReport> Amp8i20::write_ram(std::span<const Assignment> batch) {
  if (batch.empty()) return {};
  std::vector<lbp::Command> commands;
  for (const auto& a : batch) {
    commands.push_back(write_command(*a.param, a.raw));
    commands.push_back(read_command(*a.param));
  }
  const auto replies = link_.execute(commands);
  std::vector<WriteReport> reports;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    const auto& a = batch[i];
    if (!a.param->self_clearing) verify(*a.param, a.raw, replies[2 * i + 1]);
    reports.push_back({a.param, a.raw, !a.param->self_clearing, false});
  }
  return reports;
}

// The EEPROM sequence. A reset (power glitch, watchdog) drops NV access mode, and a data
// write that arrives after it lands in working memory at the EEPROM address, where a
// read-back "verifies" it. So: the mode is confirmed in a reply before the first data write
// (never pipelined behind the request), each cell's write travels with its read-back and a
// mode check, and the next cell is sent only once that check said EEPROM. The last cell's
// exchange also leaves NV mode, so a one-cell write is two exchanges.
std::vector<WriteReport> Amp8i20::write_nv(std::span<const Assignment> batch) {
  if (batch.empty()) return {};
  namespace L = lbp::local;
  const auto leave = lbp::set_nv_access(L::NvAccess::Ram);
  const auto mode = lbp::local_read(L::kGetNvAccess);
  ModeGuard guard(link_, leave, mode, "NV (EEPROM) access mode", timing_.leave_mode_tries, &unsettled_mode_);
  const std::vector<lbp::Command> enter{lbp::set_nv_access(L::NvAccess::Eeprom), mode};
  require_nv_mode(link_.execute(enter)[1], "before " + batch.front().param->name + " was to be written");
  std::vector<WriteReport> reports;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    // A cancellation between cells leaves the earlier cells written and verified.
    throw_if_cancelled();
    const auto& a = batch[i];
    std::vector<lbp::Command> commands{write_command(*a.param, a.raw), read_command(*a.param), mode};
    const bool last = i + 1 == batch.size();
    if (last) commands.insert(commands.end(), {leave, mode});
    const auto replies = link_.execute(commands);
    check_nv_cell(a, replies);
    reports.push_back({a.param, a.raw, true, true});
    if (last) guard.disarm(replies[4]);  // throws if the card did not leave NV mode (the cell is verified)
  }
  return reports;
}

void Amp8i20::check_nv_cell(const Assignment& a, const std::vector<lbp::Bytes>& replies) {
  if (replies[2].at(0) == static_cast<lbp::Byte>(lbp::local::NvAccess::Eeprom))
    return verify(*a.param, a.raw, replies[1]);
  // The card reset around this cell. Did the write land in working memory? Reading RAM at
  // the EEPROM address is a plain read; the card is in normal access mode now anyway.
  bool stray = false;
  try {
    stray = params::raw_from_bytes(*a.param, link_.execute_one(read_command(*a.param))) == a.raw;
  } catch (const link::LinkError&) {
    stray = true;  // cannot tell: assume the worst
  }
  throw NvModeLost("the 8I20 on " + link_.describe() + " reset while " + a.param->name +
                       " was being written (NV access mode was gone right after it): the EEPROM cell is "
                       "unverified" +
                       (stray ? " and the write may have reached working memory at " +
                                    lbp::hex_value(address_of(*a.param), 4)
                              : std::string()),
                   a.param->name, address_of(*a.param), stray);
}

void Amp8i20::reset(std::chrono::milliseconds wait) {
  throw_if_cancelled();
  try {
    link_.execute_one(lbp::reset_processor());
  } catch (const link::TimeoutError&) {
    // The card may reset before its reply leaves; the cookie poll below decides.
  }
  const auto deadline = Clock::now() + wait;
  while (true) {
    try {
      if (link_.execute_one(lbp::local_read(lbp::local::kGetCookie)).at(0) == lbp::local::kCookie) return;
    } catch (const link::LinkError&) {
      if (Clock::now() >= deadline)
        throw link::TimeoutError("the 8I20 on " + link_.describe() + " did not answer within " +
                                 std::to_string(wait.count()) + " ms after a reset: check its logic power");
    }
    std::this_thread::sleep_for(timing_.reset_poll.get());
  }
}

ClearFaultsResult Amp8i20::clear_faults(const WriteOptions& options, std::chrono::milliseconds deadline) {
  const auto& clear = db_.get("CLEARFAULT");
  check_write(clear, 1, options);
  ClearFaultsResult result;
  result.fault_before = static_cast<std::uint16_t>(read("FAULT").raw);
  const auto start = Clock::now();
  // From the write on, a failure is no longer "nothing written": CLEARFAULT may hold 1.
  try {
    link_.execute_one(write_command(clear, 1));
    while (read("CLEARFAULT").raw != 0) {
      throw_if_cancelled();
      if (Clock::now() - start > deadline)
        throw AmpStateError("CLEARFAULT was written and still reads 1 after " +
                            std::to_string(deadline.count()) + " ms on " + link_.describe() +
                            ": the 8I20 did not act on it (firmware busy or a wrong CLEARFAULT address?)");
      std::this_thread::sleep_for(timing_.clear_fault_poll.get());
    }
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Failure) throw;
    throw AmpStateError("CLEARFAULT 1 was sent to " + link_.describe() + ", then: " + e.what() +
                        "; it may still hold 1 (read it with `i20 get CLEARFAULT FAULT`)");
  }
  result.took = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start);
  const Param* regs[] = {&db_.get("FAULT"), &db_.get("STATUS")};
  const auto values = read(regs);
  result.fault_after = static_cast<std::uint16_t>(values[0].raw);
  result.status_after = static_cast<std::uint16_t>(values[1].raw);
  return result;
}

lbp::Bytes Amp8i20::read_memory(Space space, std::uint16_t address, std::size_t count) {
  throw_if_cancelled();
  auto commands = chunked_reads(address, count, link_.max_data_bytes());
  std::optional<ModeGuard> guard;
  if (space == Space::Eeprom) {
    const auto leave = lbp::set_nv_access(lbp::local::NvAccess::Ram);
    const auto nv_mode = lbp::local_read(lbp::local::kGetNvAccess);
    commands.insert(commands.begin(), lbp::set_nv_access(lbp::local::NvAccess::Eeprom));
    commands.insert(commands.end(), {leave, nv_mode});
    guard.emplace(link_, leave, nv_mode, "NV (EEPROM) access mode", timing_.leave_mode_tries,
                  &unsettled_mode_);
  }
  auto replies = link_.execute(commands);
  if (guard) {
    guard->disarm(replies.back());
    replies.erase(replies.begin());
    replies.resize(replies.size() - 2);
  }
  lbp::Bytes out;
  for (const auto& r : replies) out.insert(out.end(), r.begin(), r.end());
  return out;
}

lbp::Bytes Amp8i20::read_rpc_table() {
  throw_if_cancelled();
  namespace L = lbp::local;
  const std::vector<lbp::Command> sizes{lbp::local_read(L::kGetRpcSizeLow),
                                        lbp::local_read(L::kGetRpcSizeHigh)};
  const auto r = link_.execute(sizes);
  return read_rpc_table(0, r[0].at(0) | (r[1].at(0) << 8));
}

lbp::Bytes Amp8i20::read_rpc_table(std::size_t offset, std::size_t count) {
  throw_if_cancelled();
  namespace L = lbp::local;
  if (count == 0) return {};
  const auto leave = lbp::local_write(L::kSetRpcMemAccess, 0);
  const auto rpc_mode = lbp::local_read(L::kGetRpcMemAccess);
  ModeGuard guard(link_, leave, rpc_mode, "RPC memory access mode", timing_.leave_mode_tries,
                  &unsettled_mode_);
  auto commands = chunked_reads(static_cast<std::uint16_t>(offset), count, link_.max_data_bytes());
  commands.insert(commands.begin(), lbp::local_write(L::kSetRpcMemAccess, 1));
  commands.insert(commands.end(), {leave, rpc_mode});
  const auto replies = link_.execute(commands);
  guard.disarm(replies.back());
  lbp::Bytes table;
  for (std::size_t i = 1; i + 2 < replies.size(); ++i)
    table.insert(table.end(), replies[i].begin(), replies[i].end());
  return table;
}

}  // namespace i20::device
