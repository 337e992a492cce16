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

// How much the bit matters to someone whose axis just dropped out.
enum class Severity {
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
  Severity severity = Severity::Warning;
  std::string meaning;              // replaces the bit's meaning while the condition holds
  std::vector<std::string> checks;  // replace the bit's checks while it holds
};

struct BitInfo {
  Register reg = Register::Fault;
  unsigned bit = 0;          // 0..15
  std::string name;          // the manual's name (LinuxCNC-only bits: see source)
  std::string slug;          // short lowercase id for the command line
  std::string linuxcnc_pin;  // HAL pin suffix LinuxCNC shows, "" if none
  Severity severity = Severity::Fault;
  std::string meaning;              // one line
  std::vector<std::string> causes;  // most likely first
  std::vector<std::string> checks;  // what to check on the machine, in order
  bool sticky = false;              // stays set after its cause is gone
  bool maskable = false;            // a 0 in FAULTMASK keeps it off the fault output
  bool clears_while_cause_persists = false;
  std::string source;  // manual section or docs/facts.md
  std::string origin;  // "file:line" of the entry
  std::optional<Escalation> escalation;

  std::uint16_t mask() const { return static_cast<std::uint16_t>(1u << bit); }
};

// "FAULT" / "STATUS": the register names the manual and the parameter database use.
std::string_view to_string(Register reg);
// "fault" / "warning" / "info": the spelling params/faults.yaml uses.
std::string_view to_string(Severity severity);

}  // namespace i20::faults
