// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/memory.hpp"

namespace i20::profile {

const char* to_string(Memory target) {
  switch (target) {
    case Memory::Nv: return "nv";
    case Memory::Working: return "working";
    case Memory::Both: return "both";
  }
  return "?";
}

std::optional<Memory> parse_memory(std::string_view text) {
  if (text == "nv") return Memory::Nv;
  if (text == "working") return Memory::Working;
  if (text == "both") return Memory::Both;
  return std::nullopt;
}

}  // namespace i20::profile
