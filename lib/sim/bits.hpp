// SPDX-License-Identifier: GPL-2.0-or-later
// FAULT and STATUS register bits (manual "FAULT CONDITIONS", "STATUS REGISTER";
// docs/facts.md s4 for the bits only LinuxCNC names).
#pragma once

#include <cstdint>

namespace i20::sim {

namespace fault {
inline constexpr std::uint16_t kWatchdog = 1u << 0;     // communication timeout (operate mode)
inline constexpr std::uint16_t kNoEnable = 1u << 1;     // enable input not driven
inline constexpr std::uint16_t kOverTemp = 1u << 2;     // PCB temperature > 85 C
inline constexpr std::uint16_t kOverCurrent = 1u << 4;  // high side over-current
inline constexpr std::uint16_t kULoop = 1u << 5;        // U current > 125% MAXCURRENT
inline constexpr std::uint16_t kVLoop = 1u << 6;
inline constexpr std::uint16_t kWLoop = 1u << 7;
inline constexpr std::uint16_t kBusLow = 1u << 8;   // bus under-voltage (BUSUNDERV)
inline constexpr std::uint16_t kBusHigh = 1u << 9;  // bus over-voltage (BUSOVERV, settable)
inline constexpr std::uint16_t kBusMax = 1u << 10;  // bus over-voltage (fixed 400 V)
inline constexpr std::uint16_t kModule = 1u << 11;  // module over-temperature / low gate voltage
inline constexpr std::uint16_t kSerialOverrun = 1u << 14;
inline constexpr std::uint16_t kSerialFraming = 1u << 15;
// Only BUSLOVFAULT may be masked (manual "FAULT MASK").
inline constexpr std::uint16_t kMaskable = kBusLow;
// Bits the manual defines; 3, 12 and 13 are not faults.
inline constexpr std::uint16_t kDefined = 0xCFF7;
}  // namespace fault

namespace status {
inline constexpr std::uint16_t kCurrentLimited = 1u << 0;    // temperature/current limiting
inline constexpr std::uint16_t kBrakeOn = 1u << 1;           // live brake state
inline constexpr std::uint16_t kBrakeWasOn = 1u << 2;        // sticky
inline constexpr std::uint16_t kBusUnderV = 1u << 3;         // LinuxCNC name (docs/facts.md s4), live
inline constexpr std::uint16_t kDspWatchdogReset = 1u << 4;  // sticky: WDTO
inline constexpr std::uint16_t kSoftwareReset = 1u << 5;     // sticky: SWR, after 0xFE 0x5A
inline constexpr std::uint16_t kExternalReset = 1u << 6;     // sticky: EXTR, at power-up
inline constexpr std::uint16_t kNoEnable = 1u << 8;          // LinuxCNC name (docs/facts.md s4), live
inline constexpr std::uint16_t kCurrentLoopOn = 1u << 9;     // LinuxCNC name (docs/facts.md s4), live
inline constexpr std::uint16_t kSticky = kBrakeWasOn | kDspWatchdogReset | kSoftwareReset | kExternalReset;
}  // namespace status

}  // namespace i20::sim
