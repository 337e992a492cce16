// SPDX-License-Identifier: GPL-2.0-or-later
#include "params/value.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>

#include "lbp/bytes.hpp"
#include "params/text.hpp"

namespace i20::params {
namespace {

// 128-bit arithmetic for the exact decimal/scale check (GCC and Clang both have it).
__extension__ typedef unsigned __int128 U128;

// Decimal digits any exact computation below handles: 10^38 < 2^128.
constexpr std::size_t kMaxDigits = 38;
constexpr std::uint64_t kInt64Magnitude = std::uint64_t{1} << 63;  // |INT64_MIN|

bool is_digit_in(char c, int base) {
  if (c >= '0' && c <= '9') return true;
  return base == 16 && ((c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F'));
}

std::string range_text(const Param& p) {
  std::string text = std::to_string(p.min) + ".." + std::to_string(p.max);
  if (!p.unit.empty())
    text += " (" + format_engineering(p, p.min) + " .. " + format_engineering(p, p.max) + ")";
  return text;
}

[[noreturn]] void out_of_range(const Param& p, const std::string& text) {
  std::string range = std::to_string(p.min) + ".." + std::to_string(p.max);
  if (!p.unit.empty()) range += " = " + format_engineering(p, p.min) + " .. " + format_engineering(p, p.max);
  throw ValueError(text + " is out of range for " + p.name + " (" + range + ")");
}

// A signed count from a magnitude, if int64 holds it.
std::optional<std::int64_t> signed_count(bool negative, U128 magnitude) {
  if (magnitude > (negative ? kInt64Magnitude : kInt64Magnitude - 1)) return std::nullopt;
  const auto m = static_cast<std::uint64_t>(magnitude);
  if (!negative) return static_cast<std::int64_t>(m);
  return m == kInt64Magnitude ? std::numeric_limits<std::int64_t>::min() : -static_cast<std::int64_t>(m);
}

U128 pow10(std::size_t n) {
  U128 v = 1;
  while (n-- > 0) v *= 10;
  return v;
}

U128 digits_value(const std::string& digits) {
  U128 v = 0;
  for (char c : digits) v = v * 10 + static_cast<unsigned>(c - '0');
  return v;
}

std::size_t digit_count(U128 v) {
  std::size_t n = 1;
  while (v >= 10) {
    v /= 10;
    ++n;
  }
  return n;
}

// The parameter's scale as an exact decimal fraction numerator / 10^places, when it is
// one: the double nearest to that fraction, as "0.01" (1/10^2) or "0.0054931640625"
// (360/65536 = 54931640625/10^13) in the YAML give. Up to 18 decimal places.
struct DecimalScale {
  std::uint64_t numerator = 1;
  std::size_t places = 0;
};
std::optional<DecimalScale> decimal_scale(double scale) {
  double power = 1;  // 10^places, exact in a double up to 10^22
  for (std::size_t places = 0; places <= 18; ++places, power *= 10) {
    const double whole = std::round(scale * power);
    if (whole >= 1 && whole < 9.0e18 && whole / power == scale)
      return DecimalScale{static_cast<std::uint64_t>(whole), places};
  }
  return std::nullopt;
}

enum class Fit { Exact, Finer, OutOfRange };
struct Counts {
  Fit fit = Fit::Exact;
  std::int64_t value = 0;
};

// value / scale as a whole number of counts, exactly (decimal scales) or to a part in a
// million (anything else an overlay might give). A non-zero value never becomes 0 counts.
Counts counts_of(const DecimalText& d, double scale) {
  if (d.is_zero()) return {};
  if (const auto ds = decimal_scale(scale)) {
    // counts = digits * 10^(exponent + places) / numerator
    const U128 numerator = ds->numerator;
    const long shift = d.exponent + static_cast<long>(ds->places);
    U128 magnitude = 0;
    if (shift >= 0) {
      if (d.digits.size() + static_cast<std::size_t>(shift) > kMaxDigits) return {Fit::OutOfRange};
      const U128 scaled = digits_value(d.digits) * pow10(static_cast<std::size_t>(shift));
      if (scaled % numerator != 0) return {Fit::Finer};
      magnitude = scaled / numerator;
    } else {
      const auto down = static_cast<std::size_t>(-shift);
      if (digit_count(numerator) + down > kMaxDigits) return {Fit::Finer};  // divisor above the value
      const U128 divisor = numerator * pow10(down);
      const U128 value = digits_value(d.digits);
      if (value % divisor != 0) return {Fit::Finer};
      magnitude = value / divisor;
    }
    const auto count = signed_count(d.negative, magnitude);
    if (!count) return {Fit::OutOfRange};
    return {Fit::Exact, *count};
  }
  const double counts = d.to_double() / scale;
  if (!std::isfinite(counts) || std::abs(counts) > 9.0e18) return {Fit::OutOfRange};
  const double rounded = std::round(counts);
  if (rounded == 0 || std::abs(counts - rounded) > 1e-6 * std::max(1.0, std::abs(counts)))
    return {Fit::Finer};
  return {Fit::Exact, static_cast<std::int64_t>(rounded)};
}

// "0x-10", "-0x1G": hexadecimal gone wrong, which the number path would misread as 0 in
// the unit "x-10".
bool looks_hexadecimal(std::string_view t) {
  if (!t.empty() && (t[0] == '-' || t[0] == '+')) t.remove_prefix(1);
  return t.size() >= 2 && t[0] == '0' && (t[1] == 'x' || t[1] == 'X');
}

// "7,5A": the decimal comma of many locales. Saying so beats "'7' ... not ',5A'".
bool decimal_comma_follows(std::string_view rest) {
  return rest.size() > 1 && rest[0] == ',' && std::isdigit(static_cast<unsigned char>(rest[1]));
}

}  // namespace

IntegerText scan_integer(std::string_view s, bool hex_suffix) {
  IntegerText result;
  bool negative = false;
  if (!s.empty() && (s[0] == '-' || s[0] == '+')) {
    negative = s[0] == '-';
    s.remove_prefix(1);
  }
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    base = 16;
    s.remove_prefix(2);
  } else if (hex_suffix && s.size() > 1 && (s.back() == 'h' || s.back() == 'H')) {
    base = 16;
    s.remove_suffix(1);
  }
  // Digits only: a second sign ("--5", "0x-10") is not an integer, whatever from_chars allows.
  if (s.empty() || !std::all_of(s.begin(), s.end(), [&](char c) { return is_digit_in(c, base); }))
    return result;
  std::uint64_t magnitude = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), magnitude, base);
  if (ec == std::errc::result_out_of_range) {
    result.status = IntegerText::Status::OutOfRange;
    return result;
  }
  if (ec != std::errc() || ptr != s.data() + s.size()) return result;
  const auto value = signed_count(negative, magnitude);
  result.status = value ? IntegerText::Status::Ok : IntegerText::Status::OutOfRange;
  result.value = value.value_or(0);
  return result;
}

std::optional<DecimalText> scan_decimal(std::string_view text) {
  DecimalText d;
  std::size_t i = 0;
  if (i < text.size() && (text[i] == '-' || text[i] == '+')) d.negative = text[i++] == '-';
  std::string mantissa;  // every digit, the point removed
  long fraction_digits = 0;
  bool point = false;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (std::isdigit(static_cast<unsigned char>(c))) {
      mantissa.push_back(c);
      if (point) ++fraction_digits;
    } else if (c == '.' && !point) {
      point = true;
    } else {
      break;
    }
  }
  if (mantissa.empty()) return std::nullopt;
  long exponent = 0;
  // An exponent counts only with digits after it: "5e" leaves the 'e' to the unit.
  if (i + 1 < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    std::size_t j = i + 1;
    bool exponent_negative = false;
    if (j < text.size() && (text[j] == '-' || text[j] == '+')) exponent_negative = text[j++] == '-';
    if (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) {
      for (; j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])); ++j)
        exponent = std::min(exponent * 10 + (text[j] - '0'), 1'000'000L);  // far past any range
      if (exponent_negative) exponent = -exponent;
      i = j;
    }
  }
  d.length = i;
  const auto first = mantissa.find_first_not_of('0');
  if (first == std::string::npos) return d;  // zero: "0", "0.000", "-0e5"
  const auto last = mantissa.find_last_not_of('0');
  d.digits = mantissa.substr(first, last - first + 1);
  d.exponent = exponent - fraction_digits + static_cast<long>(mantissa.size() - 1 - last);
  return d;
}

double DecimalText::to_double() const {
  if (is_zero()) return 0.0;
  const std::string text = (negative ? "-" : "") + digits + "e" + std::to_string(exponent);
  return std::strtod(text.c_str(), nullptr);
}

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
  if (param.hex && param.unit.empty() && param.scale == 1.0 && raw >= 0)
    return lbp::hex_value(static_cast<std::uint64_t>(raw), static_cast<int>(param.width_bits / 4));
  if (param.scale == 1.0)
    return param.unit.empty() ? std::to_string(raw) : std::to_string(raw) + " " + param.unit;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals(param), static_cast<double>(raw) * param.scale);
  return param.unit.empty() ? std::string(buf) : std::string(buf) + " " + param.unit;
}

std::int64_t parse_raw(const Param& param, std::string_view text) {
  const auto t = trim(text);
  const auto integer = scan_integer(t);
  if (integer.status == IntegerText::Status::Ok) return integer.value;
  if (integer.status == IntegerText::Status::OutOfRange) out_of_range(param, t);
  throw ValueError(param.name + ": '" + t + "' is not an integer (raw values are decimal or 0x hexadecimal)");
}

std::int64_t parse_value(const Param& param, std::string_view text) {
  const auto t = trim(text);
  const auto integer = scan_integer(t);
  if (integer.status == IntegerText::Status::Ok) return integer.value;
  if (integer.status == IntegerText::Status::OutOfRange) out_of_range(param, t);
  if (looks_hexadecimal(t))
    throw ValueError(
        param.name + ": '" + t +
        "' is not an integer (hexadecimal is 0x and the digits 0-9, A-F, after at most one sign)");
  const auto number = scan_decimal(t);
  if (!number)
    throw ValueError(param.name + ": '" + t + "' is not a number" +
                     (param.unit.empty() ? std::string(" (give a raw integer)")
                                         : " (e.g. " + format_engineering(param, param.max) + ")"));
  const std::string_view rest = std::string_view(t).substr(number->length);
  if (decimal_comma_follows(rest))
    throw ValueError(param.name + ": '" + t + "' has a decimal comma; write the fraction with a point");
  const std::string unit = trim(rest);
  if (unit.empty()) {
    throw ValueError(param.name + ": '" + t +
                     "' is not a raw integer and has no unit; write it with its unit" +
                     (param.unit.empty() ? std::string(" (this parameter takes raw integers only)")
                                         : " (e.g. " + t + param.unit + ") or as a raw integer"));
  }
  if (param.unit.empty()) throw ValueError(param.name + " has no unit: give a raw integer, not '" + t + "'");
  if (number->digits.size() > kMaxDigits)
    throw ValueError(param.name + ": '" + t + "' has more digits than any value of it needs");
  DecimalText value = *number;
  if (iequals(unit, "m" + param.unit) && (param.unit == "V" || param.unit == "A")) {
    value.exponent -= 3;
  } else if (!iequals(unit, param.unit)) {
    throw ValueError(param.name + " is in " + param.unit + ", not '" + unit + "'");
  }
  const Counts counts = counts_of(value, param.scale);
  switch (counts.fit) {
    case Fit::Exact: return counts.value;
    case Fit::OutOfRange: out_of_range(param, t);
    case Fit::Finer: break;
  }
  throw ValueError(param.name + ": " + t + " is finer than its resolution of " +
                   format_engineering(param, 1));
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

std::string value_label(const Param& param, std::int64_t raw) {
  const auto it = param.labels.find(raw);
  return it == param.labels.end() ? std::string() : it->second;
}

std::string format_with_meaning(const Param& param, std::int64_t raw) {
  const std::string label = value_label(param, raw);
  return format_engineering(param, raw) + (label.empty() ? "" : " (" + label + ")");
}

}  // namespace i20::params
