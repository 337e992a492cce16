// SPDX-License-Identifier: GPL-2.0-or-later
// Converting between what a user types or reads ("320V", "7.5A", "0x7D00") and the raw
// integers that travel on the wire, with the database's range as the gatekeeper.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "error/error.hpp"
#include "lbp/bytes.hpp"
#include "params/param.hpp"

namespace i20::params {

// A value the database does not allow for this parameter. Nothing is sent.
class ValueError : public Error {
 public:
  explicit ValueError(const std::string& message) : Error(message, ErrorKind::BadInput), reason_(message) {}
  // "NVMAXCURRENT=15: reason", the assignment as the user typed it, then what is wrong.
  ValueError(const std::string& name, std::string_view text, const std::string& reason)
      : Error(name + "=" + std::string(text) + ": " + reason, ErrorKind::BadInput), reason_(reason) {}
  // What is wrong, without the assignment (a profile's error line names the entry itself).
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

// The unit is wrong for the parameter: not known ("7.5a"), of another quantity ("190A" for
// a voltage), or missing (MissingUnit).
class UnitError : public ValueError {
 public:
  using ValueError::ValueError;
};

// A number for a parameter with a unit, given without one ("NVMAXCURRENT=15": 15 A, 15 mA
// or 15 counts of 10 mA?). The raw form says counts: "raw:15".
class MissingUnit : public UnitError {
 public:
  using UnitError::UnitError;
};

// The one spelling of raw counts wherever a value with a unit is typed: "raw:750".
inline constexpr std::string_view kRawPrefix = "raw:";

// ---- Unit symbols: one table and one rule (SI spelling, exact case) for every parser:
// `i20 set`, profiles, and the quantities of profiles' metadata and `i20 tune`'s options.
struct UnitSymbol {
  std::string_view symbol;  // exactly as written: "mA", "ohm", "kHz"
  std::string_view base;    // the unit it is a multiple of: "A", "ohm", "Hz"
  int power_of_ten = 0;     // mA: -3, kHz: 3
  bool alias = false;       // accepted, not listed in messages ("ohms", the Greek and micro signs)
};

// Every symbol the toolkit reads: A mA; V mV; ohm ohms mohm (and the Greek sign); H mH uH
// (and the micro sign); Hz kHz; degC; deg.
const std::vector<UnitSymbol>& unit_symbols();

// `symbol` as a unit of `base` (e.g. "mA" for "A"), or nullptr with `why` set: the symbol
// is not known ("unit 'a' is not known; did you mean 'A'?" when it differs from a known one
// only in case), or is a unit of another quantity ("a current is in A or mA, not V").
const UnitSymbol* unit_of(std::string_view symbol, std::string_view base, std::string& why);

// "a current" (A), "a voltage" (V), "a resistance" (ohm), "an inductance" (H), "a frequency"
// (Hz), "a temperature" (degC), "an angle" (deg).
std::string quantity_name(std::string_view base);
// The ASCII symbols of `base`, "A or mA", "H, mH or uH".
std::string symbols_text(std::string_view base);

// Raw integer: decimal ("32000", "-5") or hexadecimal ("0x7D00", "7D00h").
// Throws ValueError naming the parameter when the text is not an integer, or when it is
// one that no 64-bit value holds ("out of range for NAME (min..max)").
std::int64_t parse_raw(const Param& param, std::string_view text);

// A value as `i20 set` and profiles take it. A parameter with a unit needs the unit ("320V",
// "320 V", "7.5A", "750mA", "45.5degC", "1.5e2V"; SI spelling, exact case) or the raw form
// "raw:N" for card counts ("raw:750", "raw:0x2EE"); a bare number is MissingUnit. A
// parameter without a unit (gains, bit masks) takes a plain integer, decimal or hex, and
// "raw:N" means the same. The value must be an exact multiple of the parameter's resolution
// ("1e-20A" is refused, not rounded to 0). No NaN, infinity, hexadecimal fractions or second
// signs. Errors are ValueError, "NAME=TEXT: reason".
std::int64_t parse_value(const Param& param, std::string_view text);

// The integer syntax shared by the value parser and the database loader: exactly one
// optional sign, then decimal digits, "0x" hexadecimal or, when `hex_suffix`, hexadecimal
// with a trailing 'h' ("7D00h"). Nothing else: no second sign, no sign after the prefix
// ("0x-10"), no spaces.
struct IntegerText {
  // OutOfRange: integer syntax, not in int64. LeadingZero: "017", which YAML 1.1 and C read
  // as octal (15) and a decimal parser as 17: ambiguous, so refused (leading_zero_reason).
  enum class Status { Ok, NotInteger, OutOfRange, LeadingZero };
  Status status = Status::NotInteger;
  std::int64_t value = 0;
};
IntegerText scan_integer(std::string_view text, bool hex_suffix = true);
// Why a number written with a leading zero ("017", "-007.5A") is refused, naming both
// readings; "" when `text` does not start with one ("0", "0.5", "0x1F" are fine).
std::string leading_zero_reason(std::string_view text);

// A plain decimal number at the start of `text`: one optional sign, digits with at most
// one '.', an optional exponent ("e-3"). Exactly: value = (-1)^negative * digits * 10^exponent,
// with `digits` free of leading and trailing zeros (empty for zero). No NaN or infinity,
// no hexadecimal. `length` is how many characters of `text` it took.
struct DecimalText {
  bool negative = false;
  std::string digits;
  long exponent = 0;
  std::size_t length = 0;

  bool is_zero() const { return digits.empty(); }
  // The nearest double (0 or +-infinity when far outside double's range).
  double to_double() const;
};
std::optional<DecimalText> scan_decimal(std::string_view text);

// Throws ValueError if raw is outside min..max or not one of the allowed values.
void check_range(const Param& param, std::int64_t raw);

// "360.00 V", "150000", "-12".
std::string format_engineering(const Param& param, std::int64_t raw);
// What a raw value means where the database has a table for it ("2.5 MBaud"), else "".
std::string value_label(const Param& param, std::int64_t raw);
// format_engineering() followed by the meaning when there is one: "9 (2.5 MBaud)".
std::string format_with_meaning(const Param& param, std::int64_t raw);
// Decimal places that show one count of the parameter's scale.
int decimals(const Param& param);

// Wire bytes (little endian, param.bytes() of them) <-> raw value, sign-extended.
std::int64_t raw_from_bytes(const Param& param, lbp::ByteView bytes);
lbp::Bytes bytes_from_raw(const Param& param, std::int64_t raw);

}  // namespace i20::params
