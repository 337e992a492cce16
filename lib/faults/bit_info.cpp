// SPDX-License-Identifier: GPL-2.0-or-later
#include "faults/bit_info.hpp"

namespace i20::faults {

std::string_view to_string(Register reg) {
  return reg == Register::Fault ? "FAULT" : "STATUS";
}

std::string_view to_string(Impact severity) {
  switch (severity) {
    case Impact::Fault: return "fault";
    case Impact::Warning: return "warning";
    case Impact::Info: return "info";
  }
  return "fault";
}

}  // namespace i20::faults
