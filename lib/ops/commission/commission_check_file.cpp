// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 commission --check FILE.hal`: what the file sets up for the 8I20 being checked (bldc's
// values, and what it wires into that bldc: the encoder, the Hall inputs, the amp), merged
// with the options. The check runs with everything the file says, so it can fail on each.
#include <algorithm>
#include <regex>
#include <set>
#include <sstream>

#include "error/error.hpp"
#include "linuxcnc/hal_design.hpp"
#include "linuxcnc/hal_file.hpp"
#include "ops/commission/commission.hpp"

namespace i20::ops {
namespace {

namespace L = linuxcnc;

std::string two_digits(unsigned n) {
  return (n < 10 ? "0" : "") + std::to_string(n);
}

// bldc.N.NAME's value as a whole number; nullopt when the file does not set it.
std::optional<std::int64_t> whole(const L::HalDesign& design, const std::string& name) {
  const auto* s = design.setting(name);
  if (s == nullptr) return std::nullopt;
  try {
    std::size_t used = 0;
    const std::string value = L::unquoted(s->value);
    const auto n = std::stoll(value, &used);
    if (used == value.size()) return n;
  } catch (const std::exception&) {
  }
  throw UsageError(s->at.text() + ": setp " + name + " needs a whole number, not '" + s->value + "'");
}

// The other pins on the signal `pin` is linked to.
std::vector<std::string> linked(const L::HalDesign& design, const std::string& pin) {
  std::vector<std::string> out;
  if (const auto* signal = design.signal_of(pin))
    for (const auto& p : signal->pins)
      if (p.name != pin) out.push_back(p.name);
  return out;
}

// The bldc instances the file sets values of (bldc.N.poles, ...).
std::set<int> bldc_instances(const L::HalDesign& design) {
  static const std::regex kBldc(R"(^bldc\.([0-9]{1,2})\..*)");
  std::set<int> out;
  std::smatch m;
  for (const auto& s : design.settings())
    if (std::regex_match(s.name, m, kBldc)) out.insert(std::stoi(m[1].str()));
  return out;
}

// The 8I20 channel bldc.N.rotor-angle (or .out) drives, from hm2's ...8i20.PORT.CHANNEL.angle.
std::optional<unsigned> amp_channel(const L::HalDesign& design, int instance) {
  static const std::regex kAmp(R"(.*\.8i20\.[0-9]+\.([0-9]+)\.(angle|current)$)");
  std::smatch m;
  const std::string bldc = "bldc." + std::to_string(instance) + ".";
  for (const char* out : {"rotor-angle", "phase-angle", "out"})
    for (const auto& pin : linked(design, bldc + out))
      if (std::regex_match(pin, m, kAmp)) return static_cast<unsigned>(std::stoul(m[1].str()));
  return std::nullopt;
}

// Which bldc instance drives the 8I20 on `channel`: the only one, or the one wired to it.
int pick_instance(const L::HalDesign& design, unsigned channel, const std::string& file) {
  const auto instances = bldc_instances(design);
  if (instances.empty())
    throw UsageError(
        file +
        ": no `setp bldc.N.poles` and `setp bldc.N.scale` lines: --check needs bldc's poles and scale");
  if (instances.size() == 1) return *instances.begin();
  for (int n : instances)
    if (amp_channel(design, n) == channel) return n;
  throw UsageError(file + ": " + std::to_string(instances.size()) +
                   " bldc instances, and none drives the 8I20 on channel " + std::to_string(channel) +
                   " (bldc.N.rotor-angle => ...8i20.PORT." + std::to_string(channel) + ".angle)");
}

// bldc's cfg letters for instance N: loadrt bldc cfg=qhi,qh gives one per instance.
std::string cfg_of(const L::HalDesign& design, int instance) {
  const auto* bldc = design.module("bldc");
  if (bldc == nullptr) return {};
  const auto it = bldc->args.find("cfg");
  if (it == bldc->args.end()) return {};
  std::stringstream list(it->second);
  std::string cfg;
  for (int n = 0; std::getline(list, cfg, ','); ++n)
    if (n == instance) return cfg;
  return {};
}

// The hm2 encoder whose rawcounts feed bldc.N.rawcounts, or, where an index capture stands
// between them (linuxcnc/index_capture.hpp), whose index-enable is bldc.N.index-enable.
std::optional<unsigned> encoder_of(const L::HalDesign& design, int instance) {
  static const std::regex kEncoder(R"(.*\.encoder\.([0-9]{1,2})\.(rawcounts|index-enable)$)");
  std::smatch m;
  const std::string bldc = "bldc." + std::to_string(instance) + ".";
  for (const char* input : {"rawcounts", "index-enable"})
    for (const auto& pin : linked(design, bldc + input))
      if (std::regex_match(pin, m, kEncoder)) return static_cast<unsigned>(std::stoul(m[1].str()));
  return std::nullopt;
}

// The inputs on bldc.N.hall1..3, named as hostmot2 names them after the board prefix
// (hm2_7i92.0.gpio.013.in -> gpio.013.in); empty unless all three are wired to hm2 pins.
std::vector<std::string> halls_of(const L::HalDesign& design, int instance) {
  static const std::regex kHm2(R"(^hm2_[^.]+\.[0-9]+\.(.+)$)");
  std::vector<std::string> out;
  std::smatch m;
  for (int h = 1; h <= 3; ++h) {
    const auto pins = linked(design, "bldc." + std::to_string(instance) + ".hall" + std::to_string(h));
    const auto it = std::find_if(pins.begin(), pins.end(),
                                 [&](const std::string& p) { return std::regex_match(p, m, kHm2); });
    if (it == pins.end()) return {};
    std::regex_match(*it, m, kHm2);
    out.push_back(m[1].str());
  }
  return out;
}

std::string comma_list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

}  // namespace

BldcSetup read_bldc_setup(const std::string& hal_text, const std::string& file, unsigned channel) {
  const L::HalDesign design(L::read_hal(hal_text, file));
  BldcSetup setup;
  setup.instance = pick_instance(design, channel, file);
  const std::string bldc = "bldc." + std::to_string(setup.instance) + ".";
  const auto poles = whole(design, bldc + "poles");
  const auto scale = whole(design, bldc + "scale");
  if (!poles || !scale)
    throw UsageError(file + ": no `setp " + bldc + "poles` and `setp " + bldc +
                     "scale` lines: --check needs bldc's poles and scale");
  if (*poles < 2 || *poles % 2 != 0)
    throw UsageError(file + ": bldc poles " + std::to_string(*poles) + " is not an even number");
  if (*scale == 0) throw UsageError(file + ": bldc scale 0");
  setup.poles = static_cast<int>(*poles);
  setup.scale = *scale;
  if (const auto pattern = whole(design, bldc + "pattern")) setup.pattern = static_cast<int>(*pattern);
  const auto offset = whole(design, bldc + "encoder-offset");
  const std::string cfg = cfg_of(design, setup.instance);
  setup.has_index = offset.has_value() && cfg.find('i') != std::string::npos;
  setup.uses_halls = cfg.find('h') != std::string::npos;
  setup.encoder_offset = offset.value_or(0);
  setup.encoder = encoder_of(design, setup.instance);
  setup.halls = halls_of(design, setup.instance);
  setup.amp_channel = amp_channel(design, setup.instance);
  if (setup.amp_channel && *setup.amp_channel != channel)
    throw UsageError(file + ": " + bldc + "rotor-angle drives the 8I20 on channel " +
                     std::to_string(*setup.amp_channel) + ", not channel " + std::to_string(channel) +
                     " (--channel): it is the setup of another axis");
  return setup;
}

BldcSetup merge_check_options(BldcSetup setup, const CommissionOptions& options, const std::string& file) {
  if (options.encoder && setup.encoder && *options.encoder != *setup.encoder)
    throw UsageError("--encoder " + std::to_string(*options.encoder) + " contradicts " + file +
                     ", which feeds bldc." + std::to_string(setup.instance) + ".rawcounts from encoder." +
                     two_digits(*setup.encoder));
  if (options.encoder) setup.encoder = options.encoder;
  if (!setup.encoder)
    throw UsageError(file + " feeds bldc." + std::to_string(setup.instance) +
                     ".rawcounts from no hostmot2 encoder: name the axis's encoder with --encoder");
  if (options.no_halls)
    throw UsageError("--no-halls with --check: the file says whether bldc reads Halls (cfg)");
  if (!options.halls.empty()) {
    if (!setup.halls.empty() && options.halls != setup.halls)
      throw UsageError("--halls " + comma_list(options.halls) + " contradicts " + file + ", which wires " +
                       comma_list(setup.halls) + " into bldc." + std::to_string(setup.instance) +
                       ".hall1..3");
    setup.halls = options.halls;
  }
  return setup;
}

}  // namespace i20::ops
