// SPDX-License-Identifier: GPL-2.0-or-later
#include "faults/bit_info.hpp"

namespace i20::faults {

std::string_view to_string(Register reg) {
  return reg == Register::Fault ? "FAULT" : "STATUS";
}

std::string_view to_string(Severity severity) {
  switch (severity) {
    case Severity::Fault: return "fault";
    case Severity::Warning: return "warning";
    case Severity::Info: return "info";
  }
  return "fault";
}

}  // namespace i20::faults
