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

// A refusal speaks the user's units first; the raw counts the card holds come second, for
// those who compare with the manual's tables.
std::string range_text(const Param& p) {
  const std::string raw = std::to_string(p.min) + ".." + std::to_string(p.max);
  if (p.unit.empty()) return raw;
  return format_engineering(p, p.min) + " .. " + format_engineering(p, p.max) + " (raw " + raw + ")";
}

std::string value_text(const Param& p, std::int64_t raw) {
  if (p.unit.empty()) return std::to_string(raw);
  return format_engineering(p, raw) + " (raw " + std::to_string(raw) + ")";
}

[[noreturn]] void out_of_range(const Param& p, const std::string& text) {
  throw ValueError(text + " is out of range for " + p.name + ": " + range_text(p));
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

std::string leading_zero_reason(std::string_view t) {
  if (!t.empty() && (t[0] == '-' || t[0] == '+')) t.remove_prefix(1);
  if (t.size() < 2 || t[0] != '0' || !std::isdigit(static_cast<unsigned char>(t[1]))) return {};
  std::size_t digits = 0;
  while (digits < t.size() && std::isdigit(static_cast<unsigned char>(t[digits]))) ++digits;
  const std::string_view number = t.substr(0, digits);
  const std::string plain(number.substr(std::min(number.find_first_not_of('0'), number.size() - 1)));
  std::string reason = "a leading zero is ambiguous: '" + std::string(number) + "' reads as " + plain;
  if (number.find_first_of("89") == std::string_view::npos && digits <= 21)
    reason += " here but as octal " + std::to_string(std::stoull(std::string(number), nullptr, 8)) +
              " in YAML 1.1 tools and C";
  else
    reason += " here, and some tools take a leading zero for octal";
  return reason + "; write " + plain + " (or 0x... for hexadecimal)";
}

IntegerText scan_integer(std::string_view s, bool hex_suffix) {
  IntegerText result;
  if (!leading_zero_reason(s).empty()) {
    result.status = IntegerText::Status::LeadingZero;
    return result;
  }
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
  if (integer.status == IntegerText::Status::LeadingZero)
    throw ValueError(param.name + ": '" + t + "': " + leading_zero_reason(t));
  throw ValueError(param.name + ": '" + t + "' is not an integer (raw values are decimal or 0x hexadecimal)");
}

const std::vector<UnitSymbol>& unit_symbols() {
  static const std::vector<UnitSymbol> table{
      {"A", "A", 0},
      {"mA", "A", -3},
      {"V", "V", 0},
      {"mV", "V", -3},
      {"ohm", "ohm", 0},
      {"mohm", "ohm", -3},
      {"ohms", "ohm", 0, true},
      {"\xCE\xA9", "ohm", 0, true},  // the Greek capital omega
      {"m\xCE\xA9", "ohm", -3, true},
      {"H", "H", 0},
      {"mH", "H", -3},
      {"uH", "H", -6},
      {"\xC2\xB5H", "H", -6, true},  // the micro sign
      {"Hz", "Hz", 0},
      {"kHz", "Hz", 3},
      {"degC", "degC", 0},
      {"deg", "deg", 0},
  };
  return table;
}

std::string quantity_name(std::string_view base) {
  if (base == "A") return "a current";
  if (base == "V") return "a voltage";
  if (base == "ohm") return "a resistance";
  if (base == "H") return "an inductance";
  if (base == "Hz") return "a frequency";
  if (base == "degC") return "a temperature";
  if (base == "deg") return "an angle";
  return "a value in " + std::string(base);
}

std::string symbols_text(std::string_view base) {
  std::vector<std::string_view> listed;
  for (const auto& u : unit_symbols())
    if (u.base == base && !u.alias) listed.push_back(u.symbol);
  if (listed.empty()) return std::string(base);
  std::string text;
  for (std::size_t i = 0; i < listed.size(); ++i)
    text += std::string(i == 0 ? "" : i + 1 == listed.size() ? " or " : ", ") + std::string(listed[i]);
  return text;
}

const UnitSymbol* unit_of(std::string_view symbol, std::string_view base, std::string& why) {
  const auto& table = unit_symbols();
  const auto exact = std::ranges::find(table, symbol, &UnitSymbol::symbol);
  const std::string in_units = quantity_name(base) + " is in " + symbols_text(base);
  if (exact != table.end()) {
    if (exact->base == base) return &*exact;
    why = in_units + ", not " + std::string(symbol);
    return nullptr;
  }
  // Case carries meaning (m is milli, M mega): "ma" or "mh" is a typo to name, not to guess.
  const auto same_letters = std::ranges::find_if(
      table, [&](const UnitSymbol& u) { return u.base == base && iequals(u.symbol, symbol); });
  why = "unit '" + std::string(symbol) + "' is not known";
  why += same_letters != table.end() ? "; did you mean '" + std::string(same_letters->symbol) + "'?"
                                     : " (" + in_units + ")";
  return nullptr;
}

namespace {

// "10 mA": one count of the parameter, in the listed unit that shows it as a whole number
// or more, else in the parameter's own unit.
std::string one_count_text(const Param& p) {
  std::string_view shown = p.unit;
  double amount = p.scale;
  for (const auto& u : unit_symbols()) {
    if (u.base != p.unit || u.alias) continue;
    const double in_unit = p.scale / std::pow(10.0, u.power_of_ten);
    if (in_unit >= 1 - 1e-12 && (amount < 1 - 1e-12 || in_unit < amount)) {
      shown = u.symbol;
      amount = in_unit;
    }
  }
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.15g", amount);
  return std::string(buf) + " " + std::string(shown);
}

// Why "15" is not enough for a parameter with a unit, and what to write instead.
std::string missing_unit_reason(const Param& p, const std::string& typed, bool whole_number) {
  std::string examples;
  const auto decimal = scan_decimal(typed);
  if (decimal && decimal->length == typed.size()) {  // "15", "7.5", not "0x2EE" or "4A38h"
    for (const auto& u : unit_symbols())
      if (u.base == p.unit && !u.alias)
        examples += (examples.empty() ? "" : ", ") + typed + std::string(u.symbol);
  } else {
    examples = "e.g. " + format_engineering(p, p.max);
  }
  std::string reason = quantity_name(p.unit) + " needs its unit (" + examples + ")";
  if (whole_number)
    reason += " or " + std::string(kRawPrefix) + typed + " for card counts (" + one_count_text(p) + " each)";
  return reason;
}

// "raw:750" (any parameter): the counts after the prefix, exactly as parse_raw reads them.
std::int64_t parse_raw_form(const Param& p, const std::string& typed) {
  const std::string counts = trim(std::string_view(typed).substr(kRawPrefix.size()));
  const auto integer = scan_integer(counts);
  if (integer.status == IntegerText::Status::Ok) return integer.value;
  if (integer.status == IntegerText::Status::OutOfRange) out_of_range(p, typed);
  if (integer.status == IntegerText::Status::LeadingZero)
    throw ValueError(p.name, typed, leading_zero_reason(counts));
  throw ValueError(
      p.name, typed,
      "raw counts are a whole number, decimal or 0x hexadecimal (e.g. raw:" + std::to_string(p.max) + ")");
}

}  // namespace

std::int64_t parse_value(const Param& param, std::string_view text) {
  const auto t = trim(text);
  const auto refuse = [&](const std::string& reason) { return ValueError(param.name, t, reason); };
  if (t.starts_with(kRawPrefix)) return parse_raw_form(param, t);
  if (t.size() >= kRawPrefix.size() && iequals(std::string_view(t).substr(0, kRawPrefix.size()), kRawPrefix))
    throw refuse("'" + t.substr(0, kRawPrefix.size()) + "' is not known; did you mean '" +
                 std::string(kRawPrefix) + "'?");
  if (const auto ambiguous = leading_zero_reason(t); !ambiguous.empty()) throw refuse(ambiguous);
  const auto integer = scan_integer(t);
  if (integer.status != IntegerText::Status::NotInteger) {
    if (!param.unit.empty()) throw MissingUnit(param.name, t, missing_unit_reason(param, t, true));
    if (integer.status == IntegerText::Status::OutOfRange) out_of_range(param, t);
    return integer.value;
  }
  if (looks_hexadecimal(t))
    throw refuse("not an integer (hexadecimal is 0x and the digits 0-9, A-F, after at most one sign)");
  const auto number = scan_decimal(t);
  if (!number)
    throw refuse(std::string("not a number") +
                 (param.unit.empty() ? " (give a whole number)"
                                     : " (e.g. " + format_engineering(param, param.max) + ")"));
  const std::string_view rest = std::string_view(t).substr(number->length);
  if (decimal_comma_follows(rest)) throw refuse("decimal comma: write the fraction with a point");
  const std::string unit = trim(rest);
  if (param.unit.empty())
    throw refuse(unit.empty() ? param.name + " takes a whole number (it has no unit)"
                              : param.name + " has no unit; give a plain whole number");
  if (unit.empty()) throw MissingUnit(param.name, t, missing_unit_reason(param, t, false));
  if (number->digits.size() > kMaxDigits)
    throw refuse("more digits than any value of " + param.name + " needs");
  std::string why;
  const UnitSymbol* symbol = unit_of(unit, param.unit, why);
  if (!symbol) throw UnitError(param.name, t, why);
  DecimalText value = *number;
  value.exponent += symbol->power_of_ten;
  const Counts counts = counts_of(value, param.scale);
  switch (counts.fit) {
    case Fit::Exact: return counts.value;
    case Fit::OutOfRange: out_of_range(param, t);
    case Fit::Finer: break;
  }
  throw refuse("finer than its resolution of " + format_engineering(param, 1));
}

void check_range(const Param& param, std::int64_t raw) {
  const std::string shown = value_text(param, raw);
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
