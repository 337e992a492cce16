// Converting between what a user types or reads ("320V", "7.5A", "0x7D00") and the raw
// integers that travel on the wire, with the database's range as the gatekeeper.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "lbp/bytes.hpp"
#include "lbp/error.hpp"
#include "params/param.hpp"

namespace i20::params {

// A value the database does not allow for this parameter. Nothing is sent.
class ValueError : public Error {
 public:
  explicit ValueError(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

// Raw integer: decimal ("32000", "-5") or hexadecimal ("0x7D00", "7D00h").
// Throws ValueError naming the parameter when the text is not an integer.
std::int64_t parse_raw(const Param& param, std::string_view text);

// A raw integer, or an engineering value with the parameter's unit ("320V", "320 V",
// "7.5A", "750mA", "45.5degC"). A bare number with a fraction is refused: the user must
// say which they mean. Values finer than the parameter's resolution are refused.
std::int64_t parse_value(const Param& param, std::string_view text);

// Throws ValueError if raw is outside min..max or not one of the allowed values.
void check_range(const Param& param, std::int64_t raw);

// "360.00 V", "150000", "-12".
std::string format_engineering(const Param& param, std::int64_t raw);
// Decimal places that show one count of the parameter's scale.
int decimals(const Param& param);

// Wire bytes (little endian, param.bytes() of them) <-> raw value, sign-extended.
std::int64_t raw_from_bytes(const Param& param, lbp::ByteView bytes);
lbp::Bytes bytes_from_raw(const Param& param, std::int64_t raw);

}  // namespace i20::params
