// SPDX-License-Identifier: GPL-2.0-or-later
// Local LBP commands 0xC0..0xFF (manual, "LOCAL LBP COMMANDS"), plus the NV access
// command the manual lists as reserved (docs/facts.md section 2).
// Reads (0xC0..0xDF) return one data byte. Writes (0xE0..0xFE) take one data byte;
// 0xFF takes none. 0xFE resets the LBP processor only when its data byte is 0x5A.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "lbp/bytes.hpp"

namespace i20::lbp::local {

// Reads
inline constexpr Byte kGetUnitAddress = 0xC0;
inline constexpr Byte kGetStatus = 0xC1;
inline constexpr Byte kGetCrcEnable = 0xC2;
inline constexpr Byte kGetCrcErrorCount = 0xC3;
inline constexpr Byte kGetRpcMemAccess = 0xCA;
inline constexpr Byte kGetCommandTimeout = 0xCB;
inline constexpr Byte kGetNvAccess = 0xCC;   // docs/facts.md: current NV access mode
inline constexpr Byte kGetCardName0 = 0xD0;  // 0xD0..0xD3: 4 character card name
inline constexpr Byte kGetCardName3 = 0xD3;
inline constexpr Byte kGetConfigName0 = 0xD4;  // 0xD4..0xD7: configuration name (some configurations)
inline constexpr Byte kGetConfigName3 = 0xD7;
inline constexpr Byte kGetLowAddress = 0xD8;
inline constexpr Byte kGetHighAddress = 0xD9;
inline constexpr Byte kGetLbpVersion = 0xDA;
inline constexpr Byte kGetUnitId = 0xDB;
inline constexpr Byte kGetRpcPitch = 0xDC;
inline constexpr Byte kGetRpcSizeLow = 0xDD;
inline constexpr Byte kGetRpcSizeHigh = 0xDE;
inline constexpr Byte kGetCookie = 0xDF;

// Writes
inline constexpr Byte kSetStatus = 0xE1;  // 0 clears the error bits
inline constexpr Byte kSetCrcEnable = 0xE2;
inline constexpr Byte kSetCrcErrorCount = 0xE3;
inline constexpr Byte kSetRpcMemAccess = 0xEA;  // non-zero enables access to the RPC table
inline constexpr Byte kSetCommandTimeout = 0xEB;
inline constexpr Byte kSetNvAccess = 0xEC;  // docs/facts.md: 0 RAM, 1 EEPROM, 2 flash
inline constexpr Byte kWriteLeds = 0xF7;
inline constexpr Byte kSetLowAddress = 0xF8;
inline constexpr Byte kSetHighAddress = 0xF9;
inline constexpr Byte kAddToAddress = 0xFA;
inline constexpr Byte kSetUnitId = 0xFD;
inline constexpr Byte kResetProcessor = 0xFE;  // only when followed by kResetKey
inline constexpr Byte kResetParser = 0xFF;     // no data byte

inline constexpr Byte kCookie = 0x5A;    // what 0xDF returns
inline constexpr Byte kResetKey = 0x5A;  // data byte that makes 0xFE reset
inline constexpr Byte kRpcPitch = 0x08;  // bytes per RPC slot on the 8I20

// LBP status bits (0xC1).
inline constexpr Byte kStatusCrcError = 0x01;
inline constexpr Byte kStatusWatchdog = 0x08;
inline constexpr Byte kStatusBufferOverflow = 0x10;
inline constexpr Byte kStatusInvalidWrite = 0x20;
inline constexpr Byte kStatusCommandTimeout = 0x40;

// NV access modes (0xEC / 0xCC).
enum class NvAccess : Byte { Ram = 0, Eeprom = 1, Flash = 2 };

// Data bytes a local command carries after its header: 0 for reads and 0xFF, else 1.
std::size_t data_bytes(Byte command);

// Human name of a documented local command ("get LBP status"), nullopt if reserved.
std::optional<std::string_view> name_of(Byte command);

// The LBP status byte (kGetStatus) in words: "no errors", or its bits ("CRC error, watchdog
// timeout").
std::string status_text(Byte status);

}  // namespace i20::lbp::local
