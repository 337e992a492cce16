#include "params/value.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "params/text.hpp"

namespace i20::params {
namespace {

std::optional<std::int64_t> try_integer(std::string_view s) {
  bool negative = false;
  if (!s.empty() && (s[0] == '-' || s[0] == '+')) {
    negative = s[0] == '-';
    s.remove_prefix(1);
  }
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    base = 16;
    s.remove_prefix(2);
  } else if (s.size() > 1 && (s.back() == 'h' || s.back() == 'H')) {
    base = 16;
    s.remove_suffix(1);
  }
  if (s.empty()) return std::nullopt;
  std::int64_t v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
  if (ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
  return negative ? -v : v;
}

std::string range_text(const Param& p) {
  std::string text = std::to_string(p.min) + ".." + std::to_string(p.max);
  if (!p.unit.empty())
    text += " (" + format_engineering(p, p.min) + " .. " + format_engineering(p, p.max) + ")";
  return text;
}

// Splits "7.5A" into 7.5 and "A"; nullopt if the text does not start with a number.
std::optional<std::pair<double, std::string>> split_number_unit(const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double number = std::strtod(begin, &end);
  if (end == begin) return std::nullopt;
  return std::make_pair(number, trim(std::string_view(end)));
}

}  // namespace

int decimals(const Param& param) {
  int places = 0;
  double step = param.scale;
  while (places < 4 && std::abs(step - std::round(step)) > 1e-9) {
    step *= 10;
    ++places;
  }
  return places;
}

std::string format_engineering(const Param& param, std::int64_t raw) {
  if (param.scale == 1.0)
    return param.unit.empty() ? std::to_string(raw) : std::to_string(raw) + " " + param.unit;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals(param), static_cast<double>(raw) * param.scale);
  return param.unit.empty() ? std::string(buf) : std::string(buf) + " " + param.unit;
}

std::int64_t parse_raw(const Param& param, std::string_view text) {
  const auto t = trim(text);
  if (auto v = try_integer(t)) return *v;
  throw ValueError(param.name + ": '" + t + "' is not an integer (raw values are decimal or 0x hexadecimal)");
}

std::int64_t parse_value(const Param& param, std::string_view text) {
  const auto t = trim(text);
  if (auto v = try_integer(t)) return *v;
  const auto parts = split_number_unit(t);
  if (!parts) throw ValueError(param.name + ": '" + t + "' is not a number");
  auto [number, unit] = *parts;
  if (unit.empty()) {
    throw ValueError(param.name + ": '" + t + "' has a fraction but no unit; write it with its unit" +
                     (param.unit.empty() ? std::string(" (this parameter takes raw integers only)")
                                         : " (e.g. " + t + param.unit + ") or as a raw integer"));
  }
  if (param.unit.empty()) throw ValueError(param.name + " has no unit: give a raw integer, not '" + t + "'");
  if (iequals(unit, "m" + param.unit) && (param.unit == "V" || param.unit == "A")) {
    number /= 1000.0;
  } else if (!iequals(unit, param.unit)) {
    throw ValueError(param.name + " is in " + param.unit + ", not '" + unit + "'");
  }
  const double counts = number / param.scale;
  const double rounded = std::round(counts);
  if (std::abs(counts - rounded) > 1e-6 * std::max(1.0, std::abs(counts)))
    throw ValueError(param.name + ": " + t + " is finer than its resolution of " +
                     format_engineering(param, 1));
  if (std::abs(rounded) > 9.0e15) throw ValueError(param.name + ": " + t + " is far out of range");
  return static_cast<std::int64_t>(rounded);
}

void check_range(const Param& param, std::int64_t raw) {
  const std::string shown = param.unit.empty()
                                ? std::to_string(raw)
                                : std::to_string(raw) + " (" + format_engineering(param, raw) + ")";
  if (raw < param.min || raw > param.max)
    throw ValueError(param.name + " = " + shown + " is outside its valid range " + range_text(param));
  if (!param.allowed.empty() && std::ranges::find(param.allowed, raw) == param.allowed.end()) {
    std::string list;
    for (auto a : param.allowed) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "0x%llX", static_cast<unsigned long long>(a));
      list += (list.empty() ? "" : ", ") + std::string(buf);
    }
    throw ValueError(param.name + " = " + shown + " is not one of the allowed values " + list);
  }
}

std::int64_t raw_from_bytes(const Param& param, lbp::ByteView bytes) {
  const auto u = static_cast<std::int64_t>(lbp::read_le(bytes.first(param.bytes())));
  if (!param.is_signed) return u;
  const std::int64_t sign = std::int64_t{1} << (param.width_bits - 1);
  return (u ^ sign) - sign;
}

lbp::Bytes bytes_from_raw(const Param& param, std::int64_t raw) {
  return lbp::to_le(static_cast<std::uint64_t>(raw), param.bytes());
}

}  // namespace i20::params
