// SPDX-License-Identifier: GPL-2.0-or-later
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
  // One word that names no bit, is no pin and resembles no name is more likely a mistyped
  // value: say how to write both. A near miss ("no-enabl") gets the bit suggestions instead.
  const bool one_word = text.find_first_of(",+.") == std::string_view::npos;
  if (one_word && !table.find(reg, text) && !table.find(text) && table.suggestions(reg, text).empty()) {
    try {
      (void)parse_register_value(text, to_string(reg));
    } catch (const BadRegisterValue& e) {
      throw BadRegisterValue(std::string(e.what()) + "; or name the set bits, e.g. no-enable or fault.no-enable");
    }
  }
  std::uint16_t value = 0;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t end = std::min(text.find_first_of(",+", begin), text.size());
    const std::string_view name = text.substr(begin, end - begin);
    if (name.empty())
      throw BadRegisterValue(std::string(to_string(reg)) + " bit list '" + std::string(text) + "' has an empty name");
    value = static_cast<std::uint16_t>(value | table.get(reg, name).mask());
    begin = end + 1;
  }
  return value;
}

}  // namespace i20::faults
