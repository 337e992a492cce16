#include "target_spec.hpp"

#include <filesystem>
#include <set>

#include "lbp/error.hpp"

namespace i20::cli {
namespace {

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

// Same device through different names (a /dev/serial/by-id link and its ttyUSBn) is one line.
std::string canonical_path(const std::string& path) {
  std::error_code ec;
  const auto resolved = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : resolved.string();
}

app::GlobalOptions without_target(app::GlobalOptions options) {
  options.port.clear();
  options.sim = false;
  options.sim_eeprom.clear();
  options.eth.clear();
  options.channel = 0;
  return options;
}

// Ethernet URLs ("eth://IP[:UDPPORT][/portP][/chN]") go to app::open_link as they are,
// which knows their syntax; here only the card matters: the channels of one Ethernet card
// share its UDP port and its SSLBP engine, so they are one line.
TargetSpec parse_eth(const std::string& text, TargetSpec spec) {
  const std::string host = text.substr(6, text.find('/', 6) - 6);
  if (host.empty())
    throw UsageError("target '" + text + "' names no card: use eth://IP/chN, e.g. eth://10.10.10.10/ch0");
  spec.options.port = text;
  spec.link_key = "eth:" + host;
  return spec;
}

}  // namespace

const char* const kTargetForms =
    "/dev/ttyUSB0 (serial port), sim (built-in simulator), sim:FILE (simulator with its EEPROM in FILE), "
    "eth://IP/chN (Ethernet card channel)";

TargetSpec parse_target(const std::string& text, const app::GlobalOptions& base, std::size_t index) {
  TargetSpec spec{text, without_target(base), {}};
  if (text.empty()) throw UsageError(std::string("empty target; use one of: ") + kTargetForms);
  if (text == "sim") {
    spec.options.sim = true;
    spec.link_key = "sim#" + std::to_string(index);  // every plain sim is its own card
    return spec;
  }
  if (starts_with(text, "sim:")) {
    if (text.size() == 4) throw UsageError("target 'sim:' needs an EEPROM file: sim:card.eeprom");
    spec.options.sim = true;
    spec.options.sim_eeprom = text.substr(4);
    spec.link_key = "sim:" + canonical_path(spec.options.sim_eeprom);
    return spec;
  }
  if (starts_with(text, "eth://")) return parse_eth(text, spec);
  if (text.find("://") != std::string::npos)
    throw UsageError("target '" + text + "': unknown scheme; use one of: " + kTargetForms);
  spec.options.port = text;
  spec.link_key = "port:" + canonical_path(text);
  return spec;
}

std::string command_flags(const TargetSpec& target) {
  const auto& o = target.options;
  if (o.sim) return o.sim_eeprom.empty() ? "--sim" : "--sim --sim-eeprom " + o.sim_eeprom;
  if (!o.eth.empty()) return "--eth " + o.eth + " --channel " + std::to_string(o.channel);
  return "--port " + o.port;  // serial ports and eth:// URLs alike
}

std::vector<TargetSpec> resolve_targets(const std::vector<std::string>& texts,
                                        const app::GlobalOptions& base) {
  const bool global = base.sim || !base.port.empty() || !base.eth.empty();
  if (global && !texts.empty())
    throw UsageError("give the cards either with --target or with --port/--sim/--eth, not both");
  std::vector<TargetSpec> targets;
  if (global) {
    TargetSpec spec{base.sim ? "sim" : !base.port.empty() ? base.port : "eth://" + base.eth, base, "global"};
    if (base.sim && !base.sim_eeprom.empty()) spec.text = "sim:" + base.sim_eeprom;
    if (!base.eth.empty()) spec.text += "/ch" + std::to_string(base.channel);
    if (!base.eth.empty()) spec.link_key = "eth:" + base.eth;
    targets.push_back(std::move(spec));
    return targets;
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < texts.size(); ++i) {
    auto spec = parse_target(texts[i], base, i);
    // Ethernet targets share a line per card, so for them a repeat is the same URL twice.
    const bool eth = spec.link_key.rfind("eth:", 0) == 0;
    if (!seen.insert(eth ? "url:" + spec.text : spec.link_key).second)
      throw UsageError("target '" + texts[i] + "' is given twice (or names the same card as another target)");
    targets.push_back(std::move(spec));
  }
  if (targets.empty())
    throw UsageError(std::string("no 8I20 given: use --target (") + kTargetForms +
                     "), or --port/--sim/--eth");
  return targets;
}

std::unique_ptr<Connection> connect(const TargetSpec& target, const params::ParamDb& db,
                                    const std::atomic<bool>* cancel, unsigned attempts) {
  auto c = std::make_unique<Connection>(Connection{db, nullptr, nullptr});
  c->link = app::open_link(target.options, c->db);
  c->amp = std::make_unique<device::Amp8i20>(*c->link, c->db, cancel);
  for (unsigned attempt = 1;; ++attempt) {
    try {
      c->amp->identify();
      return c;
    } catch (const link::LinkError&) {
      if (attempt >= attempts) throw;
    }
  }
}

}  // namespace i20::cli
