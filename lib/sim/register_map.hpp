// SPDX-License-Identifier: GPL-2.0-or-later
// Where the simulated 8I20 keeps each parameter: the only thing the simulator knows
// about names. Built in (the i20sim map that params/8i20.yaml documents), loaded from a
// ParamDb, overridden from a small text file, or shuffled, so that discovery code can be
// tested against a card whose working (RAM) addresses differ from the database.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace i20::sim {

enum class Space { Ram, Eeprom };

struct Register {
  std::string name;
  Space space = Space::Ram;
  std::uint16_t address = 0;  // byte address in its space
  unsigned width_bits = 16;   // 8, 16 or 32
  bool is_signed = false;
  std::optional<std::int64_t> default_value{};  // EEPROM image at creation / RAM at power-up
  bool read_only = false;                       // host writes are refused (LBP status bit 5)
  std::string twin{};                           // NV <-> working partner, "" if none

  unsigned bytes() const { return width_bits / 8; }
  // True if [address, address + length) shares a byte with this register.
  bool overlaps(std::uint32_t address, std::uint32_t length) const;
};

// The firmware revision i20sim reports with the built-in map (params/8i20.yaml
// `simulator_swrevision`).
inline constexpr std::uint16_t kBuiltinSwRevision = 0xE120;

class RegisterMap {
 public:
  // The i20sim map: the addresses and defaults of params/8i20.yaml, plus the defaults the
  // YAML leaves open (documented in register_map.cpp).
  static RegisterMap builtin();

  // Applies a text override file to `base`: one `NAME = ADDRESS` per line (decimal or
  // 0x hex), `revision = 0xE121` to change the SWREVISION value reported, `#` comments.
  // Throws ConfigError with the file, line and reason on anything else.
  static RegisterMap with_overrides(RegisterMap base, const std::filesystem::path& file);
  static RegisterMap with_overrides_text(RegisterMap base, std::string_view text, std::string_view origin);

  // The same parameters with the RAM addresses of the working parameters shuffled
  // (deterministically for a seed); SWREVISION and UNITNUMBER keep their public
  // addresses and SWREVISION reports a revision other than 0xE120.
  RegisterMap shuffled(std::uint64_t seed) const;

  // Adds or replaces a register (by name).
  void set(Register reg);
  const Register* find(std::string_view name) const;
  // Throws ConfigError naming the missing register.
  const Register& at(std::string_view name) const;
  const std::vector<Register>& all() const { return registers_; }

  std::uint16_t swrevision() const { return swrevision_; }
  void set_swrevision(std::uint16_t revision) { swrevision_ = revision; }

  // Throws ConfigError if two registers of one space overlap, a width is not 8/16/32, or a
  // register the simulator needs (FAULT, STATUS, CLEARFAULT, ...) is missing.
  void validate() const;

 private:
  std::vector<Register> registers_;
  std::uint16_t swrevision_ = kBuiltinSwRevision;
};

}  // namespace i20::sim
