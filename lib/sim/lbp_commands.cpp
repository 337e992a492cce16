// SPDX-License-Identifier: GPL-2.0-or-later
// What each LBP command does on the virtual 8I20 (manual "LBP", "LOCAL LBP COMMANDS",
// "RPC COMMANDS"; docs/facts.md s2 for NV access).
#include <algorithm>

#include "lbp/error.hpp"
#include "lbp/header.hpp"
#include "lbp/rpc.hpp"
#include "sim/rpc_table.hpp"
#include "sim/virtual_8i20.hpp"

namespace i20::sim {
namespace {

namespace lc = lbp::local;

constexpr char kCardName[] = "8I20";  // 0xD0..0xD3
constexpr lbp::Byte kUnitAddress = 0;

std::size_t words_touched(std::size_t offset, std::size_t length) {
  return (offset + length - 1) / 2 - offset / 2 + 1;
}

}  // namespace

lbp::Bytes Virtual8i20::dispatch(const lbp::Bytes& command, Clock::time_point t, bool& reset_requested) {
  const lbp::Byte header = command.front();
  switch (lbp::kind_of(header)) {
    case lbp::CommandKind::LocalRead: return {local_read(header)};
    case lbp::CommandKind::LocalWrite: {
      const lbp::Byte data = command.size() > 1 ? command[1] : 0;
      reset_requested = local_write(header, data);
      return {};
    }
    case lbp::CommandKind::Data: {
      const auto h = lbp::DataHeader::decode(header);
      std::optional<std::uint16_t> address;
      if (h.has_address)
        address = static_cast<std::uint16_t>(lbp::read_le(lbp::ByteView(command).subspan(1, 2)));
      return data_access(h, address, lbp::ByteView(command).subspan(1 + h.address_bytes()), t);
    }
    case lbp::CommandKind::Rpc: return run_rpc(lbp::rpc_number(header), lbp::ByteView(command).subspan(1), t);
    case lbp::CommandKind::Terminator:
    case lbp::CommandKind::Invalid: break;
  }
  return {};  // unreachable: the framer only hands out valid headers
}

lbp::Byte Virtual8i20::local_read(lbp::Byte command) const {
  switch (command) {
    case lc::kGetUnitAddress: return kUnitAddress;
    case lc::kGetStatus: return lbp_.status;
    case lc::kGetCrcEnable: return 1;  // CRCs are always enabled on the 8I20
    case lc::kGetCrcErrorCount: return lbp_.crc_errors;
    case lc::kGetRpcMemAccess: return lbp_.rpcmem ? 1 : 0;
    case lc::kGetCommandTimeout: return lbp_.command_timeout;
    case lc::kGetNvAccess: return static_cast<lbp::Byte>(lbp_.nv_access);
    case lc::kGetLowAddress: return static_cast<lbp::Byte>(lbp_.address);
    case lc::kGetHighAddress: return static_cast<lbp::Byte>(lbp_.address >> 8);
    case lc::kGetLbpVersion: return options_.lbp_version;
    case lc::kGetUnitId: return lbp_.unit_id;
    case lc::kGetRpcPitch: return lc::kRpcPitch;
    case lc::kGetRpcSizeLow: return static_cast<lbp::Byte>(kRpcTableBytes);
    case lc::kGetRpcSizeHigh: return static_cast<lbp::Byte>(kRpcTableBytes >> 8);
    case lc::kGetCookie: return lc::kCookie;
    default: break;
  }
  if (command >= lc::kGetCardName0 && command <= lc::kGetCardName3)
    return static_cast<lbp::Byte>(kCardName[command - lc::kGetCardName0]);
  return 0x00;  // reserved reads (and the configuration name the 8I20 does not have)
}

// Returns true when the command asks for a processor reset (done after the reply).
bool Virtual8i20::local_write(lbp::Byte command, lbp::Byte data) {
  switch (command) {
    case lc::kSetStatus: lbp_.status = data; break;
    case lc::kSetCrcEnable: break;  // CRC checking cannot be turned off on the 8I20
    case lc::kSetCrcErrorCount: lbp_.crc_errors = data; break;
    case lc::kSetRpcMemAccess: lbp_.rpcmem = data != 0; break;
    case lc::kSetCommandTimeout:
      lbp_.command_timeout = data;
      apply_command_timeout();
      break;
    case lc::kSetNvAccess:
      if (data > static_cast<lbp::Byte>(lc::NvAccess::Flash))
        lbp_.status |= lc::kStatusInvalidWrite;
      else
        lbp_.nv_access = static_cast<lc::NvAccess>(data);
      break;
    case lc::kWriteLeds: lbp_.leds = data; break;
    case lc::kSetLowAddress: lbp_.address = static_cast<std::uint16_t>((lbp_.address & 0xFF00) | data); break;
    case lc::kSetHighAddress:
      lbp_.address = static_cast<std::uint16_t>((lbp_.address & 0x00FF) | (data << 8));
      break;
    case lc::kAddToAddress: lbp_.address = static_cast<std::uint16_t>(lbp_.address + data); break;
    case lc::kSetUnitId: lbp_.unit_id = data; break;
    case lc::kResetProcessor: return data == lc::kResetKey;  // any other byte: no reset
    case lc::kResetParser: break;                            // the framer is at a command boundary already
    default: break;                                          // reserved writes are accepted and ignored
  }
  return false;
}

lbp::Bytes Virtual8i20::data_access(const lbp::DataHeader& h, std::optional<std::uint16_t> address,
                                    lbp::ByteView data, Clock::time_point t) {
  if (address) lbp_.address = *address;  // an explicit address loads the pointer
  const std::uint16_t start = lbp_.address;
  const std::size_t n = h.data_bytes();
  lbp::Bytes reply;
  if (h.write) {
    if (!write_bytes(start, data.first(n), t)) lbp_.status |= lc::kStatusInvalidWrite;
  } else {
    for (std::size_t i = 0; i < n; ++i) reply.push_back(read_byte(static_cast<std::uint16_t>(start + i)));
  }
  if (h.auto_increment) lbp_.address = static_cast<std::uint16_t>(start + n);
  return reply;
}

lbp::Bytes Virtual8i20::run_rpc(unsigned number, lbp::ByteView stream, Clock::time_point t) {
  // The framer cut the command against the table as it is now (Framer::still_fits), so
  // the list decodes and the stream holds its data; a mismatch here is a framer bug, and
  // executing anyway would read past the command.
  const lbp::RpcList list = lbp::decode_rpc_list(rpc_table_, number);
  if (list.stream_bytes != stream.size())
    throw ProtocolError("internal: RPC " + std::to_string(number) + " framed with " +
                        std::to_string(stream.size()) + " stream bytes, its list takes " +
                        std::to_string(list.stream_bytes));
  lbp::Bytes reply;
  std::size_t used = 0;
  for (const auto& step : list.steps) {
    lbp::ByteView data;
    if (step.header.write && step.header.rpc_includes_data) {
      data = step.table_data;
    } else if (step.header.write) {
      data = stream.subspan(used, step.header.data_bytes());
      used += step.header.data_bytes();
    }
    const lbp::Bytes part = data_access(step.header, step.address, data, t);
    reply.insert(reply.end(), part.begin(), part.end());
    if (!powered_) break;
  }
  return reply;
}

lbp::Byte Virtual8i20::read_byte(std::uint16_t address) const {
  if (lbp_.rpcmem && address < rpc_table_.size()) return rpc_table_[address];
  switch (lbp_.nv_access) {
    case lc::NvAccess::Eeprom: {
      const auto& e = amplifier_.eeprom();
      return address < e.size() ? e.at(address) : 0xFF;
    }
    case lc::NvAccess::Flash: return 0xFF;  // flash is not modelled: reads as erased
    case lc::NvAccess::Ram: break;
  }
  return amplifier_.ram(address);
}

bool Virtual8i20::write_bytes(std::uint16_t address, lbp::ByteView data, Clock::time_point t) {
  if (lbp_.rpcmem && address < rpc_table_.size()) {
    if (std::size_t{address} + data.size() > rpc_table_.size()) return false;  // past the table end
    std::copy(data.begin(), data.end(), rpc_table_.begin() + address);
    return true;
  }
  switch (lbp_.nv_access) {
    case lc::NvAccess::Flash: return false;
    case lc::NvAccess::Ram:
      if (amplifier_.ram_write_protected(address, data.size())) return false;
      amplifier_.write_ram(address, data);
      return true;
    case lc::NvAccess::Eeprom: break;
  }
  if (std::size_t{address} + data.size() > amplifier_.eeprom().size()) return false;
  ++stats_.eeprom_writes;
  if (injection_.eeprom_power_loss != EepromPowerLoss::None) {
    if (injection_.eeprom_power_loss == EepromPowerLoss::Torn)
      amplifier_.eeprom().write(address, data.first(1));
    injection_.eeprom_power_loss = EepromPowerLoss::None;
    trace("power lost during an EEPROM write (injected)");
    power_off();
    return true;
  }
  const Clock::time_point start = busy_until_.value_or(t);
  busy_until_ = start + options_.eeprom_word_time * static_cast<long>(words_touched(address, data.size()));
  eeprom_pending_.push_back({address, lbp::Bytes(data.begin(), data.end())});
  return true;
}

}  // namespace i20::sim
