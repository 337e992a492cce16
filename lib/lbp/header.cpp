// SPDX-License-Identifier: GPL-2.0-or-later
#include "lbp/header.hpp"

#include <string>

#include "lbp/error.hpp"

namespace i20::lbp {
namespace {

constexpr Byte kTypeMask = 0xC0;
constexpr Byte kTypeData = 0x40;
constexpr Byte kTypeRpc = 0x80;
constexpr Byte kWriteBit = 0x20;
constexpr Byte kRidBit = 0x10;
constexpr Byte kAutoIncBit = 0x08;
constexpr Byte kAddressBit = 0x04;
constexpr Byte kSizeMask = 0x03;

std::string hex_byte(Byte b) {
  static constexpr char digits[] = "0123456789ABCDEF";
  return std::string("0x") + digits[b >> 4] + digits[b & 0x0F];
}

}  // namespace

CommandKind kind_of(Byte header) {
  if (header == 0x00) return CommandKind::Terminator;
  switch (header & kTypeMask) {
    case 0x00: return CommandKind::Invalid;
    case kTypeData: return CommandKind::Data;
    case kTypeRpc: return CommandKind::Rpc;
    default: return (header & 0x20) ? CommandKind::LocalWrite : CommandKind::LocalRead;
  }
}

std::size_t byte_count(DataSize size) {
  return std::size_t{1} << static_cast<unsigned>(size);
}

std::optional<DataSize> data_size_for(std::size_t bytes) {
  switch (bytes) {
    case 1: return DataSize::One;
    case 2: return DataSize::Two;
    case 4: return DataSize::Four;
    case 8: return DataSize::Eight;
    default: return std::nullopt;
  }
}

Byte DataHeader::encode() const {
  Byte b = kTypeData | static_cast<Byte>(size);
  if (write) b |= kWriteBit;
  if (rpc_includes_data) b |= kRidBit;
  if (auto_increment) b |= kAutoIncBit;
  if (has_address) b |= kAddressBit;
  return b;
}

DataHeader DataHeader::decode(Byte header) {
  if ((header & kTypeMask) != kTypeData)
    throw ProtocolError(hex_byte(header) + " is not an LBP data read/write header (bits 7..6 must be 01)");
  DataHeader h;
  h.write = header & kWriteBit;
  h.rpc_includes_data = header & kRidBit;
  h.auto_increment = header & kAutoIncBit;
  h.has_address = header & kAddressBit;
  h.size = static_cast<DataSize>(header & kSizeMask);
  return h;
}

Byte rpc_command(unsigned number) {
  if (number >= kRpcCount)
    throw UsageError("RPC number " + std::to_string(number) + " is out of range: the 8I20 stores RPCs 0..63");
  return static_cast<Byte>(kTypeRpc | number);
}

unsigned rpc_number(Byte header) {
  if (kind_of(header) != CommandKind::Rpc)
    throw ProtocolError(hex_byte(header) + " is not an LBP RPC command (bits 7..6 must be 10)");
  return header & 0x3F;
}

}  // namespace i20::lbp
