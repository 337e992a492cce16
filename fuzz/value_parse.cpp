// SPDX-License-Identifier: GPL-2.0-or-later
// Value and quantity parsing (lib/params/value, lib/profile/quantity): what users type
// after `i20 set NAME=` and in profiles. Bad text is refused with ValueError (or a reason
// string); text that is accepted means exactly what it says:
//  - an engineering value equals its counts times the scale (no rounding: a value finer
//    than the resolution is refused), and formatting the counts parses back to them when
//    the format shows every digit;
//  - a quantity is finite, positive and reads back from its own formatting.
//
// Input: [parameter index][quantity kind][text]
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "params/param_db.hpp"
#include "params/text.hpp"
#include "params/value.hpp"
#include "profile/quantity.hpp"

namespace {

using namespace i20;

const params::ParamDb& db() {
  static const params::ParamDb instance = params::ParamDb::builtin();
  return instance;
}

void value(const params::Param& p, const std::string& text) {
  const std::int64_t raw = params::parse_value(p, text);
  const std::string t = params::trim(text);
  const auto decimal = params::scan_decimal(t);
  const bool plain_integer = params::scan_integer(t).status == params::IntegerText::Status::Ok;
  if (!plain_integer && decimal) {
    // An engineering value: counts * scale is the number typed (in the unit, or milli-unit).
    double typed = decimal->to_double();
    const std::string unit = params::trim(std::string_view(t).substr(decimal->length));
    if (unit.size() > p.unit.size()) typed /= 1000.0;  // "mA", "mV"
    const double counts = typed / p.scale;
    fuzz::require(std::abs(counts - static_cast<double>(raw)) <= 1e-6 * std::max(1.0, std::abs(counts)),
                  "an engineering value converts to its counts");
  }
  bool in_range = true;
  try {
    params::check_range(p, raw);
  } catch (const params::ValueError&) {
    in_range = false;
  }
  // A value the card can hold is shown with every digit (scales 1 and 0.01), so the shown
  // text loads back exactly. (Far outside the range, a double no longer holds the counts.)
  const std::string shown = params::format_engineering(p, raw);
  if (in_range && (p.scale == 1.0 || p.scale == 0.01))
    fuzz::require(params::parse_value(p, shown) == raw, "a formatted value parses back to its counts");
}

void raw(const params::Param& p, const std::string& text) {
  const std::int64_t v = params::parse_raw(p, text);
  const auto scanned = params::scan_integer(params::trim(text));
  fuzz::require(scanned.status == params::IntegerText::Status::Ok && scanned.value == v,
                "parse_raw accepts exactly scan_integer's integers");
}

void quantity(profile::Quantity kind, const std::string& text) {
  std::string why;
  const auto v = profile::parse_quantity(kind, text, why);
  if (!v) {
    fuzz::require(!why.empty(), "a refused quantity says why");
    return;
  }
  fuzz::require(std::isfinite(*v) && *v > 0, "an accepted quantity is finite and positive");
  const std::string shown = profile::format_quantity(kind, *v);
  std::string why_again;
  const auto again = profile::parse_quantity(kind, shown, why_again);
  fuzz::require(again.has_value(), "a formatted quantity parses back");
  fuzz::require(std::abs(*again - *v) <= 1e-5 * *v, "a formatted quantity keeps its value");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  const auto& all = db().all();
  const auto& p = all[in.byte() % all.size()];
  const auto kind = static_cast<profile::Quantity>(in.byte() % 5);  // Current .. Frequency
  const std::string text = in.rest_text();
  fuzz::expect_only_toolkit_errors([&] { value(p, text); });
  fuzz::expect_only_toolkit_errors([&] { raw(p, text); });
  fuzz::expect_no_exception([&] { quantity(kind, text); });
  return 0;
}
