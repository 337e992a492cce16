// SPDX-License-Identifier: GPL-2.0-or-later
// What the knowledge base says about one bit of the 8I20's FAULT or STATUS register.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace i20::faults {

// STATUS sticky bits that record why the DSP last started (manual, STATUS REGISTER):
// WDTO (4, hardware watchdog), SWR (5, software reset), EXTR (6, external reset). A bit
// rising between two readings means the card restarted and reloaded its NV values.
inline constexpr std::uint16_t kStatusWdto = 1u << 4;
inline constexpr std::uint16_t kStatusSwr = 1u << 5;
inline constexpr std::uint16_t kStatusExtr = 1u << 6;
inline constexpr std::uint16_t kResetCauseBits = kStatusWdto | kStatusSwr | kStatusExtr;

enum class Register { Fault, Status };

// How much the bit matters to someone whose axis just dropped out (the table's `severity:`;
// a profile finding's severity is profile::Severity, another scale).
enum class Impact {
  Fault,    // the drive is (or was) off because of it
  Warning,  // the drive may run, but something is not right
  Info,     // normal operation; shown for completeness
};

// A level condition that makes a bit worse than its usual severity: the bit is set while a
// measured value sits above a threshold parameter (BRAKESTATUS while the bus is above
// BRAKEONV: the brake resistor takes the supply's power continuously). From the YAML's
// `escalate:` block; what it means lives there, not in code.
struct Escalation {
  std::string measured;            // parameter read live, e.g. "BUSV"
  std::vector<std::string> above;  // thresholds, any of which the measured value is above
  std::string unit;                // of the measured value and the thresholds, for the evidence
  Impact severity = Impact::Warning;
  std::string meaning;              // replaces the bit's meaning while the condition holds
  std::vector<std::string> checks;  // replace the bit's checks while it holds
};

// How live readings show whether a latched FAULT bit's cause is there now. From the YAML's
// `live_check:` block; lib/ops/diagnosis judges it. Either a measured value against a
// threshold (BUSV below BUSUNDERV), or a STATUS bit that follows the condition, or both (the
// measurement first; the STATUS bit when the measurement or its threshold is not known).
struct LiveCheck {
  enum class Compare { Above, Below };
  std::string measured;                   // parameter read live, e.g. "BUSV"; "" = STATUS only
  Compare compare = Compare::Above;       // the cause is present while measured is above/below
  std::string threshold_param;            // parameter read live, e.g. "BUSUNDERV", or ...
  std::optional<double> threshold_value;  // ... a limit of the card itself (85 degC)
  bool fixed = false;                     // the manual calls the limit fixed (MAXBUSVFAULT: 400 V)
  std::string unit;                       // of measured and the threshold, for the evidence
  std::string advice;                     // appended to the evidence while the cause is present
  std::string status_slug;                // STATUS bit set while the condition holds ("" = none)
  std::optional<unsigned> status_bit;     // that bit, resolved by the loader
  std::string status_set;                 // what a set STATUS bit shows
  std::string status_clear;               // what a clear one shows; "" = a clear bit proves nothing
  std::string origin;                     // "file:line" of the block
};

struct BitInfo {
  Register reg = Register::Fault;
  unsigned bit = 0;          // 0..15
  std::string name;          // the manual's name (LinuxCNC-only bits: see source)
  std::string slug;          // short lowercase id for the command line
  std::string linuxcnc_pin;  // HAL pin suffix LinuxCNC shows, "" if none
  Impact severity = Impact::Fault;
  std::string meaning;              // one line
  std::vector<std::string> causes;  // most likely first
  std::vector<std::string> checks;  // what to check on the machine, in order
  bool sticky = false;              // stays set after its cause is gone
  bool maskable = false;            // a 0 in FAULTMASK keeps it off the fault output
  bool clears_while_cause_persists = false;
  std::string source;  // manual section or docs/facts.md
  std::string origin;  // "file:line" of the entry
  std::optional<Escalation> escalation;
  std::optional<LiveCheck> live_check;  // FAULT bits only

  std::uint16_t mask() const { return static_cast<std::uint16_t>(1u << bit); }
};

// "FAULT" / "STATUS": the register names the manual and the parameter database use.
std::string_view to_string(Register reg);
// "fault" / "warning" / "info": the spelling params/faults.yaml uses.
std::string_view to_string(Impact severity);

}  // namespace i20::faults
