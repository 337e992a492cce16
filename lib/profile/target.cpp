// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/target.hpp"

namespace i20::profile {

const char* to_string(Target target) {
  switch (target) {
    case Target::Nv: return "nv";
    case Target::Working: return "working";
    case Target::Both: return "both";
  }
  return "?";
}

std::optional<Target> parse_target(std::string_view text) {
  if (text == "nv") return Target::Nv;
  if (text == "working") return Target::Working;
  if (text == "both") return Target::Both;
  return std::nullopt;
}

}  // namespace i20::profile
