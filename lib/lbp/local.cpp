// SPDX-License-Identifier: GPL-2.0-or-later
#include "lbp/local.hpp"

#include <utility>

#include "lbp/header.hpp"

namespace i20::lbp::local {

std::size_t data_bytes(Byte command) {
  return (kind_of(command) == CommandKind::LocalWrite && command != kResetParser) ? 1 : 0;
}

std::optional<std::string_view> name_of(Byte command) {
  switch (command) {
    case kGetUnitAddress: return "get unit address";
    case kGetStatus: return "get LBP status";
    case kGetCrcEnable: return "get CRC enable";
    case kGetCrcErrorCount: return "get CRC error count";
    case kGetRpcMemAccess: return "get RPCMEM access flag";
    case kGetCommandTimeout: return "get command timeout";
    case kGetNvAccess: return "get NV access mode";
    case 0xD0:
    case 0xD1:
    case 0xD2:
    case 0xD3: return "get card name character";
    case 0xD4:
    case 0xD5:
    case 0xD6:
    case 0xD7: return "get configuration name character";
    case kGetLowAddress: return "get low address";
    case kGetHighAddress: return "get high address";
    case kGetLbpVersion: return "get LBP version";
    case kGetUnitId: return "get unit ID";
    case kGetRpcPitch: return "get RPC pitch";
    case kGetRpcSizeLow: return "get RPC size low byte";
    case kGetRpcSizeHigh: return "get RPC size high byte";
    case kGetCookie: return "get LBP cookie";
    case kSetStatus: return "set LBP status";
    case kSetCrcEnable: return "set CRC enable";
    case kSetCrcErrorCount: return "set CRC error count";
    case kSetRpcMemAccess: return "set RPCMEM access flag";
    case kSetCommandTimeout: return "set command timeout";
    case kSetNvAccess: return "set NV access mode";
    case kWriteLeds: return "write LEDs";
    case kSetLowAddress: return "set low address";
    case kSetHighAddress: return "set high address";
    case kAddToAddress: return "add to address";
    case kSetUnitId: return "set unit ID";
    case kResetProcessor: return "reset LBP processor";
    case kResetParser: return "reset LBP parser";
    default: return std::nullopt;
  }
}

std::string status_text(Byte status) {
  if (status == 0) return "no errors";
  std::string text;
  const std::pair<Byte, const char*> bits[] = {{kStatusCrcError, "CRC error"},
                                               {kStatusWatchdog, "watchdog timeout"},
                                               {kStatusBufferOverflow, "buffer overflow"},
                                               {kStatusInvalidWrite, "invalid write"},
                                               {kStatusCommandTimeout, "command timeout"}};
  for (const auto& [bit, name] : bits)
    if (status & bit) text += (text.empty() ? "" : ", ") + std::string(name);
  return text;
}

}  // namespace i20::lbp::local
