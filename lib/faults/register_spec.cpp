#include "faults/register_spec.hpp"

#include <algorithm>
#include <cctype>
#include <string>

#include "faults/register_value.hpp"

namespace i20::faults {
namespace {

bool looks_numeric(std::string_view text) {
  return !text.empty() && std::isdigit(static_cast<unsigned char>(text.front()));
}

}  // namespace

std::uint16_t parse_register_spec(std::string_view text, Register reg, const FaultTable& table) {
  if (looks_numeric(text)) return parse_register_value(text, to_string(reg));
  std::uint16_t value = 0;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t end = std::min(text.find_first_of(",+", begin), text.size());
    const std::string_view name = text.substr(begin, end - begin);
    if (name.empty())
      throw BadRegisterValue(std::string(to_string(reg)) + " bit list '" + std::string(text) +
                             "' has an empty name");
    value = static_cast<std::uint16_t>(value | table.get(reg, name).mask());
    begin = end + 1;
  }
  return value;
}

}  // namespace i20::faults
