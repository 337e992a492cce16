// SPDX-License-Identifier: GPL-2.0-or-later
// The symbolic parameter database, loaded from YAML (params/8i20.yaml and overlays).
//
// The loader is strict: a bad file is rejected with "file:line: reason" (unknown keys,
// duplicate names, overlapping addresses, ranges that do not fit the width, ...).
// Overlays (--params FILE, the per-user file, `i20 discover` output) override keys of
// existing entries or add new ones; an overlay with a top-level `swrevision` applies
// only in the database for_firmware() returns for that revision.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "error/error.hpp"
#include "params/param.hpp"

namespace i20::params {

// A database or overlay file is malformed. what() is "file:line: reason".
class ParamFileError : public Error {
 public:
  explicit ParamFileError(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

// A name not in the database. what() suggests the closest names.
class UnknownParameter : public Error {
 public:
  UnknownParameter(const std::string& name, std::vector<std::string> suggestions);
  const std::vector<std::string>& suggestions() const { return suggestions_; }

 private:
  std::vector<std::string> suggestions_;
};

// A LinuxCNC name for one 16-bit half of a 32-bit parameter (nvkqilo, nvkqihi, ...). what()
// names the whole parameter to use instead and how the halves make it up.
class HalfAlias : public Error {
 public:
  explicit HalfAlias(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

class ParamDb {
 public:
  // The database shipped with the toolkit (params/8i20.yaml, compiled in).
  static ParamDb builtin();
  static ParamDb load_file(const std::filesystem::path& path);
  static ParamDb load_string(std::string_view yaml, const std::string& source_name);

  void apply_overlay_file(const std::filesystem::path& path);
  void apply_overlay_string(std::string_view yaml, const std::string& source_name);

  // The database as it applies to a card reporting this revision: the overlays waiting
  // for it merged in, and address_confirmed() judged against it. A new value: this one
  // stays as loaded, so any number of cards can be resolved from one database.
  ParamDb for_firmware(std::uint16_t swrevision) const;
  // Addresses the card itself names (its pre-loaded RPC table, decoded read-only), taken
  // as confirmed for this database's firmware. A parameter whose unconfirmed address
  // overlaps one of them loses that address (it was a guess the card contradicts).
  struct Evidence {
    std::string name;
    std::uint16_t address = 0;
    std::string source;  // "the card's pre-loaded RPC table (RPC 0)"
  };
  ParamDb with_evidence(const std::vector<Evidence>& evidence) const;
  std::optional<std::uint16_t> firmware() const { return firmware_; }
  bool address_confirmed(const Param& param) const { return param.address_confirmed(firmware_); }

  // Case-insensitive lookup by name or alias (`nvmaxcurrent` finds NVMAXCURRENT). A half
  // alias (`nvkqilo`) finds nothing: i20 handles the 32-bit value whole.
  const Param* find(std::string_view name) const;
  // Throws UnknownParameter with suggestions, or HalfAlias for a half alias.
  const Param& get(std::string_view name) const;
  // The alias `name` is (nullptr for a database name or an unknown one), and its parameter.
  struct AliasOf {
    const Param* param = nullptr;
    const Alias* alias = nullptr;
  };
  AliasOf alias(std::string_view name) const;
  std::vector<std::string> suggestions(std::string_view name, std::size_t max = 3) const;
  // The parameter whose bytes cover `address` in `space`, if any.
  const Param* at_address(Space space, std::uint16_t address) const;

  const std::vector<Param>& all() const { return params_; }
  std::optional<std::uint16_t> simulator_swrevision() const { return simulator_swrevision_; }
  const std::vector<std::string>& sources() const { return sources_; }

 private:
  struct PendingOverlay {
    std::uint16_t swrevision;
    std::string yaml;
    std::string source;
  };

  void merge(std::string_view yaml, const std::string& source, bool is_base);
  void check_consistency(const std::string& source) const;
  template <class Fail>
  void check_aliases(const Param& p, const Fail& fail) const;

  std::vector<Param> params_;
  std::optional<std::uint16_t> simulator_swrevision_;
  std::optional<std::uint16_t> firmware_;
  std::vector<PendingOverlay> pending_;
  std::vector<std::string> sources_;
};

// Overlay files applied by default when present: $I20_PARAMS, then
// $XDG_CONFIG_HOME/i20/params.yaml (or ~/.config/i20/params.yaml).
std::vector<std::filesystem::path> default_overlay_paths();

}  // namespace i20::params
