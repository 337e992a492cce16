// SPDX-License-Identifier: GPL-2.0-or-later
// The fault and status knowledge base: every defined bit of the 8I20's FAULT and STATUS
// registers, loaded from YAML (params/faults.yaml, compiled in).
//
// The loader is strict: unknown or repeated keys, duplicate bits, names, slugs or LinuxCNC
// pins, bits above 15 and missing advice are rejected with "file:line: reason", so a
// typo in the knowledge base fails the build's tests instead of misleading someone at a
// machine.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "faults/bit_info.hpp"
#include "faults/error.hpp"

namespace i20::faults {

class FaultTable {
 public:
  // The table shipped with the toolkit (params/faults.yaml compiled in). Parsed once; the
  // instance is immutable, so sharing it is safe.
  static const FaultTable& builtin();
  static FaultTable load_file(const std::filesystem::path& path);
  static FaultTable load_string(std::string_view yaml, const std::string& source_name);

  // Entries of one register, in bit order.
  const std::vector<BitInfo>& bits(Register reg) const;
  // Register-wide advice (how faults clear, what the fault output does, ...).
  const std::vector<std::string>& notes(Register reg) const;
  // The bit's entry, or nullptr if the manual defines no such bit (reserved).
  const BitInfo* find(Register reg, unsigned bit) const;
  // By slug, manual name or LinuxCNC pin (case-insensitive) in either register. A pin may
  // carry its hostmot2 device prefix (hm2_7i96s.0.8i20.0.0.fault.no-enable), as halshow shows it.
  const BitInfo* find(std::string_view key) const;
  // As above within one register; a decimal bit number ("8") is accepted too.
  const BitInfo* find(Register reg, std::string_view key) const;
  // As find(reg, key), but throws UnknownBit with suggestions.
  const BitInfo& get(Register reg, std::string_view key) const;

  // Bits the manual defines (1 = defined).
  std::uint16_t defined_bits(Register reg) const;
  // FAULT bits that FAULTMASK can mask.
  std::uint16_t maskable_bits() const;
  // Closest slugs to a mistyped key, best first.
  std::vector<std::string> suggestions(Register reg, std::string_view key, std::size_t max = 3) const;

  // The fixed limit in the live check of the FAULT bit `key` (slug, name or bit number):
  // MAXBUSVFAULT's 400 V. Throws FaultFileError when that bit has no numeric limit, so a
  // table that lost it fails loudly instead of dropping a safety check.
  double fixed_limit(std::string_view key) const;

  const std::string& source() const { return source_; }

 private:
  FaultTable() = default;

  std::vector<BitInfo> fault_;
  std::vector<BitInfo> status_;
  std::vector<std::string> fault_notes_;
  std::vector<std::string> status_notes_;
  std::string source_;
};

}  // namespace i20::faults
