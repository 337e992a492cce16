// SPDX-License-Identifier: GPL-2.0-or-later
#include "params/param_db.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "params/closest.hpp"
#include "params/data_file.hpp"
#include "params/text.hpp"
#include "params/value.hpp"
#include "params/yaml_problem.hpp"

namespace i20::params {
namespace {

const std::set<std::string> kParamKeys{"name",   "space",         "address", "width",       "signed",
                                       "unit",   "scale",         "min",     "max",         "allowed",
                                       "access", "default",       "twin",    "description", "provenance",
                                       "guard",  "self_clearing", "aliases", "format",      "labels"};
const std::set<std::string> kRequiredNewKeys{"name",   "space",  "address",     "width",
                                             "signed", "access", "description", "provenance"};
const std::set<std::string> kBaseTopKeys{"schema", "device", "simulator_swrevision", "parameters"};
const std::set<std::string> kOverlayTopKeys{"schema", "device", "swrevision", "note", "parameters"};

// Reads YAML and annotates every error with file and line.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& reason) const {
    throw ParamFileError(where(at) + ": " + reason);
  }
  std::string where(const YAML::Node& at) const {
    const auto mark = at.Mark();
    return source_ + ":" + (mark.line >= 0 ? std::to_string(mark.line + 1) : std::string("?"));
  }

  std::string text(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, "'" + key + "' must be a single value");
    return node.Scalar();
  }

  // Integers in decimal or 0x hexadecimal, with one optional sign (value.hpp's syntax).
  std::int64_t integer(const YAML::Node& node, const std::string& key) const {
    const std::string s = text(node, key);
    const auto parsed = scan_integer(s, /*hex_suffix=*/false);
    if (parsed.status == IntegerText::Status::OutOfRange)
      fail(node, "'" + key + "' is out of range for a 64-bit integer: '" + s + "'");
    if (parsed.status == IntegerText::Status::LeadingZero)
      fail(node, "'" + key + "': " + leading_zero_reason(s));
    if (parsed.status != IntegerText::Status::Ok)
      fail(node, "'" + key + "' must be an integer, not '" + s + "'");
    return parsed.value;
  }

  double real(const YAML::Node& node, const std::string& key) const {
    const std::string s = text(node, key);
    char* end = nullptr;
    const double value = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size())
      fail(node, "'" + key + "' must be a number, not '" + s + "'");
    return value;
  }

  bool boolean(const YAML::Node& node, const std::string& key) const {
    const std::string s = text(node, key);
    if (s == "true") return true;
    if (s == "false") return false;
    fail(node, "'" + key + "' must be true or false, not '" + s + "'");
  }

  void only_keys(const YAML::Node& map, const std::set<std::string>& allowed, const std::string& what) const {
    for (const auto& kv : map) {
      const auto key = kv.first.Scalar();
      if (!allowed.contains(key)) {
        std::string list;
        for (const auto& k : allowed) list += (list.empty() ? "" : ", ") + k;
        fail(kv.first, "unknown key '" + key + "' in " + what + " (allowed: " + list + ")");
      }
    }
  }

  const std::string& source() const { return source_; }

 private:
  std::string source_;
};

void read_provenance(const Reader& r, const YAML::Node& node, Provenance& out) {
  if (!node.IsMap())
    r.fail(node, "'provenance' must be a map {source: ..., confirmed_on: all | [revisions]}");
  r.only_keys(node, {"source", "confirmed_on"}, "provenance");
  if (!node["source"]) r.fail(node, "provenance needs a 'source' saying where the address comes from");
  if (!node["confirmed_on"])
    r.fail(node, "provenance needs 'confirmed_on' (all, or a list of SWREVISION values, [] if none)");
  out.source = r.text(node["source"], "source");
  const auto confirmed = node["confirmed_on"];
  out.confirmed_on.clear();
  out.confirmed_on_all = false;
  if (confirmed.IsScalar()) {
    if (confirmed.Scalar() != "all")
      r.fail(confirmed, "'confirmed_on' must be 'all' or a list of SWREVISION values");
    out.confirmed_on_all = true;
  } else if (confirmed.IsSequence()) {
    for (const auto& rev : confirmed) {
      const auto v = r.integer(rev, "confirmed_on");
      if (v < 0 || v > 0xFFFF) r.fail(rev, "SWREVISION values are 16 bit");
      out.confirmed_on.push_back(static_cast<std::uint16_t>(v));
    }
  } else {
    r.fail(confirmed, "'confirmed_on' must be 'all' or a list of SWREVISION values");
  }
}

// `aliases: [nvmaxcurrent]`, or for a 32-bit value split in two by LinuxCNC
// `aliases: [{name: nvkqilo, bits: 0-15}, {name: nvkqihi, bits: 16-31}]`.
std::vector<Alias> read_aliases(const Reader& r, const YAML::Node& node) {
  if (!node.IsSequence()) r.fail(node, "'aliases' must be a list of names");
  std::vector<Alias> aliases;
  for (const auto& item : node) {
    Alias a;
    YAML::Node name = item;
    if (item.IsMap()) {
      r.only_keys(item, {"name", "bits"}, "an alias");
      if (!item["name"] || !item["bits"])
        r.fail(item, "an alias map needs 'name' and 'bits' (0-15 or 16-31)");
      const auto bits = r.text(item["bits"], "bits");
      if (bits == "0-15")
        a.part = Alias::Part::Low16;
      else if (bits == "16-31")
        a.part = Alias::Part::High16;
      else
        r.fail(item["bits"], "'bits' of an alias must be 0-15 or 16-31, not '" + bits + "'");
      name = item["name"];
    }
    a.name = r.text(name, "aliases");
    const bool plain = !a.name.empty() && std::ranges::all_of(a.name, [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
    });
    if (!plain) r.fail(name, "alias '" + a.name + "' must be one word (letters, digits, _ - .)");
    aliases.push_back(std::move(a));
  }
  return aliases;
}

// The bits a value has on the wire: 8, 16 or 32, checked before anything shifts by it.
unsigned read_width(const Reader& r, const YAML::Node& node) {
  const auto w = r.integer(node, "width");
  if (w != 8 && w != 16 && w != 32)
    r.fail(node, "'width' must be 8, 16 or 32 bits, not " + std::to_string(w));
  return static_cast<unsigned>(w);
}

// Every value a `width`-bit field holds; width is 8, 16 or 32 (read_width).
std::pair<std::int64_t, std::int64_t> width_range(unsigned width, bool is_signed) {
  if (width == 0 || width > 32) throw ParamFileError("internal: width_range(" + std::to_string(width) + ")");
  if (is_signed) return {-(std::int64_t{1} << (width - 1)), (std::int64_t{1} << (width - 1)) - 1};
  return {0, (std::int64_t{1} << width) - 1};
}

// Applies the keys present in `node` to `p`.
void read_fields(const Reader& r, const YAML::Node& node, Param& p) {
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    const YAML::Node& v = kv.second;
    if (key == "name") {
      p.name = upper(r.text(v, key));
    } else if (key == "space") {
      const auto s = r.text(v, key);
      if (s == "ram")
        p.space = Space::Ram;
      else if (s == "eeprom")
        p.space = Space::Eeprom;
      else
        r.fail(v, "'space' must be ram or eeprom, not '" + s + "'");
    } else if (key == "address") {
      if (v.IsNull()) {
        p.address.reset();
      } else {
        const auto a = r.integer(v, key);
        if (a < 0 || a > 0xFFFF)
          r.fail(v, "address " + std::to_string(a) + " is outside the 16-bit LBP address space");
        p.address = static_cast<std::uint16_t>(a);
      }
    } else if (key == "width") {
      p.width_bits = read_width(r, v);
    } else if (key == "signed") {
      p.is_signed = r.boolean(v, key);
    } else if (key == "unit") {
      p.unit = v.IsNull() ? "" : r.text(v, key);
    } else if (key == "scale") {
      p.scale = r.real(v, key);
      if (!(p.scale > 0)) r.fail(v, "'scale' must be positive");
    } else if (key == "min") {
      p.min = r.integer(v, key);
    } else if (key == "max") {
      p.max = r.integer(v, key);
    } else if (key == "allowed") {
      if (!v.IsSequence()) r.fail(v, "'allowed' must be a list of raw values");
      p.allowed.clear();
      for (const auto& a : v) p.allowed.push_back(r.integer(a, key));
    } else if (key == "access") {
      const auto s = r.text(v, key);
      if (s == "ro")
        p.access = Access::ReadOnly;
      else if (s == "rw")
        p.access = Access::ReadWrite;
      else
        r.fail(v, "'access' must be ro or rw, not '" + s + "'");
    } else if (key == "default") {
      p.default_value = r.integer(v, key);
    } else if (key == "twin") {
      p.twin = upper(r.text(v, key));
    } else if (key == "description") {
      p.description = r.text(v, key);
    } else if (key == "provenance") {
      read_provenance(r, v, p.provenance);
    } else if (key == "guard") {
      p.guard = r.text(v, key);
    } else if (key == "self_clearing") {
      p.self_clearing = r.boolean(v, key);
    } else if (key == "aliases") {
      p.aliases = read_aliases(r, v);
    } else if (key == "labels") {
      if (!v.IsMap()) r.fail(v, "'labels' must map raw values to what they mean, e.g. {9: 2.5 MBaud}");
      p.labels.clear();
      for (const auto& kv : v) p.labels[r.integer(kv.first, key)] = r.text(kv.second, key);
    } else if (key == "format") {
      const auto f = r.text(v, key);
      if (f != "hex" && f != "decimal") r.fail(v, "'format' must be hex or decimal, not '" + f + "'");
      p.hex = f == "hex";
    }
  }
  p.origin = r.where(node);
}

std::string read_text_file(const std::filesystem::path& path) {
  auto file = read_data_file(path, "parameter file");
  if (!file.problem.empty()) throw ParamFileError(path.string() + ": " + file.problem);
  return std::move(file.text);
}

YAML::Node parse_yaml(std::string_view yaml, const std::string& source) {
  return params::load_yaml(yaml, source, [](const std::string& where, const std::string& problem) {
    throw ParamFileError(where + ": " + problem);
  });
}

}  // namespace

UnknownParameter::UnknownParameter(const std::string& name, std::vector<std::string> suggestions)
    : Error(
          [&] {
            std::string msg = "unknown parameter '" + name + "'";
            if (!suggestions.empty()) {
              msg += ": did you mean ";
              for (std::size_t i = 0; i < suggestions.size(); ++i)
                msg += (i ? (i + 1 == suggestions.size() ? " or " : ", ") : "") + suggestions[i];
              msg += "?";
            } else {
              msg += " (list them all with `i20 dump` or see params/8i20.yaml)";
            }
            return msg;
          }(),
          ErrorKind::BadInput),
      suggestions_(std::move(suggestions)) {}

ParamDb ParamDb::load_file(const std::filesystem::path& path) {
  return load_string(read_text_file(path), path.string());
}

ParamDb ParamDb::load_string(std::string_view yaml, const std::string& source_name) {
  ParamDb db;
  db.merge(yaml, source_name, /*is_base=*/true);
  return db;
}

void ParamDb::apply_overlay_file(const std::filesystem::path& path) {
  apply_overlay_string(read_text_file(path), path.string());
}

void ParamDb::apply_overlay_string(std::string_view yaml, const std::string& source_name) {
  const auto root = parse_yaml(yaml, source_name);
  if (root.IsMap() && root["swrevision"]) {
    const Reader r(source_name);
    const auto rev = r.integer(root["swrevision"], "swrevision");
    if (rev < 0 || rev > 0xFFFF) r.fail(root["swrevision"], "'swrevision' is a 16-bit value");
    if (firmware_ != rev) {
      // Validate now so a bad file fails at load time, apply when the card says so.
      ParamDb probe = *this;
      probe.merge(yaml, source_name, false);
      pending_.push_back({static_cast<std::uint16_t>(rev), std::string(yaml), source_name});
      return;
    }
  }
  merge(yaml, source_name, /*is_base=*/false);
}

ParamDb ParamDb::for_firmware(std::uint16_t swrevision) const {
  ParamDb db = *this;
  db.firmware_ = swrevision;
  db.pending_.clear();
  for (const auto& overlay : pending_) {
    if (overlay.swrevision == swrevision)
      db.merge(overlay.yaml, overlay.source, false);
    else
      db.pending_.push_back(overlay);
  }
  return db;
}

ParamDb ParamDb::with_evidence(const std::vector<Evidence>& evidence) const {
  ParamDb db = *this;
  for (const auto& e : evidence) {
    Param* p = nullptr;
    for (auto& q : db.params_)
      if (q.name == upper(e.name)) p = &q;
    if (!p) continue;
    p->address = e.address;
    p->provenance.source = e.source;
    p->provenance.confirmed_on_all = false;
    p->provenance.confirmed_on.clear();
    if (db.firmware_) p->provenance.confirmed_on.push_back(*db.firmware_);
    p->origin = e.source;
  }
  // A guessed address the card contradicts is no address at all.
  for (auto& q : db.params_) {
    if (!q.address || db.address_confirmed(q)) continue;
    for (const auto& e : evidence) {
      const Param* named = db.find(e.name);
      if (!named || named->space != q.space || &q == named) continue;
      const auto q_end = std::size_t{*q.address} + q.bytes();
      const auto e_end = std::size_t{e.address} + named->bytes();
      if (*q.address < e_end && e.address < q_end) {
        q.address.reset();
        q.provenance.source += "; dropped: the card's RPC table puts " + named->name + " there";
        break;
      }
    }
  }
  db.check_consistency("card evidence");
  return db;
}

void ParamDb::merge(std::string_view yaml, const std::string& source, bool is_base) {
  const Reader r(source);
  const auto root = parse_yaml(yaml, source);
  if (!root.IsMap()) throw ParamFileError(source + ":1: expected a map with a 'parameters' list");
  r.only_keys(root, is_base ? kBaseTopKeys : kOverlayTopKeys,
              is_base ? "a parameter database" : "an overlay");
  if (root["schema"] && r.integer(root["schema"], "schema") != 1)
    r.fail(root["schema"], "unsupported schema version (this toolkit reads schema 1)");
  if (is_base && root["simulator_swrevision"]) {
    const auto rev = r.integer(root["simulator_swrevision"], "simulator_swrevision");
    if (rev < 0 || rev > 0xFFFF)
      r.fail(root["simulator_swrevision"], "'simulator_swrevision' is a 16-bit value");
    simulator_swrevision_ = static_cast<std::uint16_t>(rev);
  }
  const auto list = root["parameters"];
  if (!list || !list.IsSequence()) r.fail(root, "'parameters' must be a list of parameter entries");

  std::set<std::string> seen_here;
  for (const auto& entry : list) {
    if (!entry.IsMap()) r.fail(entry, "each parameter must be a map of keys");
    r.only_keys(entry, kParamKeys, "a parameter");
    if (!entry["name"]) r.fail(entry, "parameter entry without a 'name'");
    const std::string name = upper(r.text(entry["name"], "name"));
    if (!seen_here.insert(name).second) r.fail(entry, "duplicate parameter name '" + name + "'");
    auto existing = std::ranges::find(params_, name, &Param::name);
    if (existing != params_.end()) {
      if (is_base) r.fail(entry, "duplicate parameter name '" + name + "'");
      read_fields(r, entry, *existing);
      continue;
    }
    for (const auto& key : kRequiredNewKeys)
      if (!entry[key]) r.fail(entry, "parameter '" + name + "' lacks required key '" + key + "'");
    Param p;
    const auto [lo, hi] = width_range(read_width(r, entry["width"]), r.boolean(entry["signed"], "signed"));
    p.min = lo;  // full width unless the entry narrows it
    p.max = hi;
    read_fields(r, entry, p);
    params_.push_back(std::move(p));
  }
  check_consistency(source);
  sources_.push_back(source);
}

// Every alias names exactly one parameter, is no other parameter's name, and splits only
// 32-bit values. It may spell its own parameter's name (nvmaxcurrent): then it only records
// that hostmot2 uses the same name.
template <class Fail>
void ParamDb::check_aliases(const Param& p, const Fail& fail) const {
  for (const auto& a : p.aliases) {
    const auto key = upper(a.name);
    if (a.part != Alias::Part::Whole && p.width_bits != 32)
      fail("alias '" + a.name + "' names a 16-bit half, but " + p.name + " is not 32 bit");
    for (const auto& q : params_) {
      if (q.name == key && &q != &p) fail("alias '" + a.name + "' is the name of " + q.name);
      for (const auto& b : q.aliases)
        if (&b != &a && upper(b.name) == key)
          fail("alias '" + a.name + "' is also an alias of " + q.name + " (" + q.origin + ")");
    }
  }
}

void ParamDb::check_consistency(const std::string& source) const {
  for (const auto& p : params_) {
    const auto fail = [&](const std::string& reason) {
      throw ParamFileError(p.origin + ": " + p.name + ": " + reason);
    };
    const auto [lo, hi] = width_range(p.width_bits, p.is_signed);
    if (p.min > p.max) fail("min " + std::to_string(p.min) + " is above max " + std::to_string(p.max));
    if (p.min < lo || p.max > hi)
      fail("range " + std::to_string(p.min) + ".." + std::to_string(p.max) + " does not fit a " +
           (p.is_signed ? "signed " : "unsigned ") + std::to_string(p.width_bits) + "-bit value (" +
           std::to_string(lo) + ".." + std::to_string(hi) + ")");
    for (auto a : p.allowed)
      if (a < p.min || a > p.max) fail("allowed value " + std::to_string(a) + " is outside min..max");
    if (p.default_value) {
      if (*p.default_value < p.min || *p.default_value > p.max)
        fail("default " + std::to_string(*p.default_value) + " is outside min..max");
      if (!p.allowed.empty() && std::ranges::find(p.allowed, *p.default_value) == p.allowed.end())
        fail("default is not one of the allowed values");
    }
    if (p.address && std::size_t{*p.address} + p.bytes() > 0x10000) fail("address range runs past 0xFFFF");
    if (!p.twin.empty()) {
      const Param* twin = find(p.twin);
      if (!twin) fail("twin '" + p.twin + "' is not in the database");
      if (twin->twin != p.name) fail("twin '" + p.twin + "' does not name " + p.name + " back as its twin");
      if (twin->width_bits != p.width_bits || twin->is_signed != p.is_signed)
        fail("twin '" + p.twin + "' has a different width or signedness");
    }
    if (p.provenance.source.empty()) fail("provenance needs a source");
    check_aliases(p, fail);
    for (const auto& q : params_) {
      if (&q == &p || q.space != p.space || !p.address || !q.address || q.name < p.name) continue;
      const auto p_end = std::size_t{*p.address} + p.bytes();
      const auto q_end = std::size_t{*q.address} + q.bytes();
      if (*p.address < q_end && *q.address < p_end)
        fail("address overlaps " + q.name + " (" + q.origin + ") in " + to_string(p.space) + " space");
    }
  }
  (void)source;
}

const Param* ParamDb::find(std::string_view name) const {
  const auto key = upper(name);
  const auto it = std::ranges::find(params_, key, &Param::name);
  if (it != params_.end()) return &*it;
  const AliasOf a = alias(name);
  return a.alias && a.alias->part == Alias::Part::Whole ? a.param : nullptr;
}

ParamDb::AliasOf ParamDb::alias(std::string_view name) const {
  const auto key = upper(name);
  for (const auto& p : params_)
    for (const auto& a : p.aliases)
      if (upper(a.name) == key) return {&p, &a};
  return {};
}

const Param& ParamDb::get(std::string_view name) const {
  if (const Param* p = find(name)) return *p;
  if (const AliasOf a = alias(name); a.alias) {
    const bool low = a.alias->part == Alias::Part::Low16;
    std::string other;
    for (const auto& b : a.param->aliases)
      if (b.part != Alias::Part::Whole && b.part != a.alias->part) other = b.name;
    const std::string lo = low ? a.alias->name : other, hi = low ? other : a.alias->name;
    throw HalfAlias(a.alias->name + " is LinuxCNC's name for bits " + (low ? "0-15" : "16-31") + " of " +
                    a.param->name + ", a 32-bit value that i20 reads and writes whole: use " + a.param->name +
                    (lo.empty() || hi.empty() ? ""
                                              : " (" + lo + " = " + a.param->name + " & 0xFFFF, " + hi +
                                                    " = " + a.param->name + " >> 16)"));
  }
  throw UnknownParameter(std::string(name), suggestions(name));
}

std::vector<std::string> ParamDb::suggestions(std::string_view name, std::size_t max) const {
  std::vector<Candidate> candidates;
  for (const auto& p : params_) {
    Candidate c{p.name, {p.name}};
    for (const auto& a : p.aliases) c.spellings.push_back(a.name);
    candidates.push_back(std::move(c));
  }
  auto near = closest(name, candidates, max);
  // A half alias (nvkqilo) means its 32-bit parameter, whatever is spelled alike.
  if (const AliasOf a = alias(name); a.alias && a.alias->part != Alias::Part::Whole) {
    std::erase(near, a.param->name);
    near.insert(near.begin(), a.param->name);
    if (near.size() > max) near.resize(max);
  }
  return near;
}

const Param* ParamDb::at_address(Space space, std::uint16_t address) const {
  for (const auto& p : params_)
    if (p.space == space && p.address && address >= *p.address && address < *p.address + p.bytes()) return &p;
  return nullptr;
}

std::vector<std::filesystem::path> default_overlay_paths() {
  std::vector<std::filesystem::path> paths;
  if (const char* env = std::getenv("I20_PARAMS"); env && *env) paths.emplace_back(env);
  std::filesystem::path config;
  if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg && *xdg)
    config = xdg;
  else if (const char* home = std::getenv("HOME"); home && *home)
    config = std::filesystem::path(home) / ".config";
  if (!config.empty()) {
    const auto user = config / "i20" / "params.yaml";
    std::error_code ec;
    if (std::filesystem::exists(user, ec)) paths.push_back(user);
  }
  return paths;
}

}  // namespace i20::params
