// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/register_map.hpp"

#include <algorithm>
#include <fstream>
#include <random>
#include <sstream>

#include "sim/error.hpp"

namespace i20::sim {
namespace {

Register nv(std::string name, std::uint16_t address, unsigned width, std::int64_t def, std::string twin) {
  return {std::move(name), Space::Eeprom, address, width, false, def, false, std::move(twin)};
}

Register ram(std::string name, std::uint16_t address, unsigned width, bool is_signed, bool read_only,
             std::optional<std::int64_t> def = std::nullopt, std::string twin = {}) {
  return {std::move(name), Space::Ram, address, width, is_signed, def, read_only, std::move(twin)};
}

// Registers the device logic reads or writes itself; a map without them cannot run.
constexpr std::string_view kRequired[] = {"FAULT",       "STATUS",    "CLEARFAULT", "FAULTMASK", "BUSV",
                                          "TEMPERATURE", "ANGLE",     "QSETPOINT",  "BUSUNDERV", "BUSOVERV",
                                          "BRAKEONV",    "BRAKEOFFV", "SWREVISION", "UNITNUMBER"};

// Registers that keep their public addresses when a map is shuffled (docs/facts.md s2):
// the EEPROM, and the RAM registers LinuxCNC reads on every real 8I20 (MAXCURRENT at
// 0x08E8 to scale its current pin, SWREVISION, UNITNUMBER).
bool is_fixed(const Register& r) {
  return r.space == Space::Eeprom || r.name == "SWREVISION" || r.name == "UNITNUMBER" ||
         r.name == "MAXCURRENT";
}

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

std::uint32_t parse_number(const std::string& text, const std::string& where) {
  try {
    std::size_t used = 0;
    const unsigned long value = std::stoul(text, &used, 0);
    if (used != text.size() || value > 0xFFFF) throw std::invalid_argument("range");
    return static_cast<std::uint32_t>(value);
  } catch (const std::exception&) {
    throw ConfigError(where + ": '" + text + "' is not a 16-bit number (write 2164 or 0x0874)");
  }
}

}  // namespace

bool Register::overlaps(std::uint32_t start, std::uint32_t length) const {
  const std::uint32_t begin = address;
  const std::uint32_t end = begin + bytes();
  return start < end && begin < start + length;
}

// Defaults the YAML does not give, chosen here and documented in the README of the
// simulator: NVMAXCURRENT 1000 (10 A), NVKQIL/NVKDIL 2000, NVBUSUNDERVMAX 4000 (40 V,
// the level at which an under-voltage fault's cause is gone), NVDEADZONE 0.
RegisterMap RegisterMap::builtin() {
  RegisterMap m;
  m.registers_ = {
      nv("NVMAXCURRENT", 2, 16, 1000, "MAXCURRENT"),
      nv("NVBAUDRATE", 6, 16, 9, ""),
      nv("NVKQP", 10, 16, 50, "KQP"),
      nv("NVKQI", 12, 32, 150000, "KQI"),
      nv("NVKQIL", 16, 16, 2000, "KQIL"),
      nv("NVKDP", 18, 16, 50, "KDP"),
      nv("NVKDI", 20, 32, 150000, "KDI"),
      nv("NVKDIL", 24, 16, 2000, "KDIL"),
      nv("NVBUSUNDERV", 34, 16, 3500, "BUSUNDERV"),
      nv("NVBUSUNDERVMAX", 36, 16, 4000, "BUSUNDERVMAX"),
      nv("NVBUSOVERV", 38, 16, 38500, "BUSOVERV"),
      nv("NVBRAKEONV", 40, 16, 36000, "BRAKEONV"),
      nv("NVBRAKEOFFV", 42, 16, 34000, "BRAKEOFFV"),
      nv("NVDEADZONE", 44, 16, 0, "DEADZONE"),
      ram("FAULT", 0x0800, 16, false, true),
      ram("STATUS", 0x0802, 16, false, true),
      ram("CLEARFAULT", 0x0804, 16, false, false, 0),
      ram("FAULTMASK", 0x0806, 16, false, false, 0xFFFF),
      ram("BUSV", 0x0808, 16, false, true),
      ram("TEMPERATURE", 0x080A, 16, false, true),
      ram("ANGLE", 0x080C, 16, false, false, 0),
      ram("QSETPOINT", 0x080E, 16, true, false, 0),
      ram("DSETPOINT", 0x0810, 16, true, false, 0),
      ram("MAXCURRENT", 0x08E8, 16, false, false, std::nullopt, "NVMAXCURRENT"),
      ram("KQP", 0x0814, 16, false, false, std::nullopt, "NVKQP"),
      ram("KQI", 0x0816, 32, false, false, std::nullopt, "NVKQI"),
      ram("KQIL", 0x081A, 16, false, false, std::nullopt, "NVKQIL"),
      ram("KDP", 0x081C, 16, false, false, std::nullopt, "NVKDP"),
      ram("KDI", 0x081E, 32, false, false, std::nullopt, "NVKDI"),
      ram("KDIL", 0x0822, 16, false, false, std::nullopt, "NVKDIL"),
      ram("DEADZONE", 0x0824, 16, false, false, std::nullopt, "NVDEADZONE"),
      ram("BUSUNDERV", 0x0826, 16, false, false, std::nullopt, "NVBUSUNDERV"),
      ram("BUSUNDERVMAX", 0x0828, 16, false, false, std::nullopt, "NVBUSUNDERVMAX"),
      ram("BUSOVERV", 0x082A, 16, false, false, std::nullopt, "NVBUSOVERV"),
      ram("BRAKEONV", 0x082C, 16, false, false, std::nullopt, "NVBRAKEONV"),
      ram("BRAKEOFFV", 0x082E, 16, false, false, std::nullopt, "NVBRAKEOFFV"),
      ram("SWREVISION", 2164, 16, false, true),
      ram("UNITNUMBER", 2344, 32, false, true),
  };
  return m;
}

RegisterMap RegisterMap::with_overrides(RegisterMap base, const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw ConfigError("cannot read address map " + file.string() + ": check the path");
  std::stringstream text;
  text << in.rdbuf();
  return with_overrides_text(std::move(base), text.str(), file.string());
}

RegisterMap RegisterMap::with_overrides_text(RegisterMap base, std::string_view text,
                                             std::string_view origin) {
  std::istringstream lines{std::string(text)};
  std::string line;
  for (unsigned number = 1; std::getline(lines, line); ++number) {
    const std::string where = std::string(origin) + ":" + std::to_string(number);
    const std::string content = trim(line.substr(0, line.find('#')));
    if (content.empty()) continue;
    const auto eq = content.find('=');
    if (eq == std::string::npos)
      throw ConfigError(where + ": expected NAME = ADDRESS, got '" + content + "'");
    std::string name = trim(content.substr(0, eq));
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::toupper(c); });
    const std::uint32_t value = parse_number(trim(content.substr(eq + 1)), where);
    if (name == "REVISION") {
      base.swrevision_ = static_cast<std::uint16_t>(value);
      continue;
    }
    Register reg = base.at(name);
    reg.address = static_cast<std::uint16_t>(value);
    base.set(std::move(reg));
  }
  base.validate();
  return base;
}

RegisterMap RegisterMap::shuffled(std::uint64_t seed) const {
  RegisterMap out = *this;
  std::mt19937_64 rng(seed);
  std::vector<std::size_t> movable;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> used;  // [begin, end) taken in RAM
  for (std::size_t i = 0; i < out.registers_.size(); ++i) {
    const auto& r = out.registers_[i];
    if (r.space != Space::Ram) continue;
    if (is_fixed(r))
      used.emplace_back(r.address, r.address + r.bytes());
    else
      movable.push_back(i);
  }
  // Fisher-Yates with raw engine output keeps the result identical on every standard library.
  for (std::size_t i = movable.size(); i > 1; --i) std::swap(movable[i - 1], movable[rng() % i]);
  // Working parameters land on even addresses in 0x0400..0x0FFF, outside the RPC table.
  constexpr std::uint32_t kLow = 0x0400, kHigh = 0x1000;
  for (std::size_t index : movable) {
    auto& r = out.registers_[index];
    for (;;) {
      const std::uint32_t candidate = kLow + 2 * static_cast<std::uint32_t>(rng() % ((kHigh - kLow) / 2));
      const std::uint32_t end = candidate + r.bytes();
      const bool clash = end > kHigh || std::any_of(used.begin(), used.end(), [&](const auto& u) {
                           return candidate < u.second && u.first < end;
                         });
      if (clash) continue;
      r.address = static_cast<std::uint16_t>(candidate);
      used.emplace_back(candidate, end);
      break;
    }
  }
  out.swrevision_ = static_cast<std::uint16_t>(0xE121 + seed % 0x1EDE);  // never 0xE120
  out.validate();
  return out;
}

void RegisterMap::set(Register reg) {
  for (auto& r : registers_) {
    if (r.name == reg.name) {
      r = std::move(reg);
      return;
    }
  }
  registers_.push_back(std::move(reg));
}

const Register* RegisterMap::find(std::string_view name) const {
  for (const auto& r : registers_)
    if (r.name == name) return &r;
  return nullptr;
}

const Register& RegisterMap::at(std::string_view name) const {
  if (const auto* r = find(name)) return *r;
  throw ConfigError("the register map has no parameter named " + std::string(name));
}

void RegisterMap::validate() const {
  for (auto name : kRequired) at(name);
  for (std::size_t i = 0; i < registers_.size(); ++i) {
    const auto& a = registers_[i];
    if (a.width_bits != 8 && a.width_bits != 16 && a.width_bits != 32)
      throw ConfigError(a.name + " has width " + std::to_string(a.width_bits) + ": use 8, 16 or 32");
    if (std::uint32_t{a.address} + a.bytes() > 0x10000)
      throw ConfigError(a.name + " at " + std::to_string(a.address) +
                        " runs past the end of the address space");
    for (std::size_t j = i + 1; j < registers_.size(); ++j) {
      const auto& b = registers_[j];
      if (a.space == b.space && a.overlaps(b.address, b.bytes()))
        throw ConfigError(a.name + " and " + b.name + " overlap at address " + std::to_string(b.address) +
                          ": give one of them another address");
    }
  }
}

}  // namespace i20::sim
