// SPDX-License-Identifier: GPL-2.0-or-later
// Fault tables written in a test: a valid bit entry, and what loading one says when it is
// refused (one line, "FILE:LINE: reason").
#pragma once

#include <gtest/gtest.h>

#include <cctype>
#include <string>

#include "faults/fault_table.hpp"

namespace i20::faults::testing {

// A valid bit entry, 11 lines from its "- bit:" line; `extra` adds or repeats keys. The
// name derives from the slug unless given, so distinct slugs give distinct names.
inline std::string bit(unsigned n, const std::string& slug, const std::string& extra = "",
                       const std::string& name = "") {
  std::string upper = name;
  if (upper.empty())
    for (char c : slug)
      upper += c == '-' ? '_' : static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return "  - bit: " + std::to_string(n) + "\n    name: " + upper + "\n    slug: " + slug +
         "\n    severity: fault\n    meaning: test\n    causes: [a cause]\n    checks: [a check]\n"
         "    sticky: true\n    maskable: false\n    clears_while_cause_persists: true\n    source: test\n" +
         extra;
}

// The loader's message for `yaml` (loaded as "bad.yaml"), or "" when it loads.
inline std::string error_of(const std::string& yaml) {
  try {
    FaultTable::load_string(yaml, "bad.yaml");
  } catch (const FaultFileError& e) {
    return e.what();
  }
  return "";
}

// Refused with one line that starts "bad.yaml:LINE: " and names `reason`.
inline ::testing::AssertionResult rejected_at(const std::string& yaml, int line, const std::string& reason) {
  const auto msg = error_of(yaml);
  const auto where = "bad.yaml:" + std::to_string(line) + ": ";
  if (msg.rfind(where, 0) != 0 || msg.find(reason) == std::string::npos ||
      msg.find('\n') != std::string::npos)
    return ::testing::AssertionFailure()
           << "expected one line '" << where << "..." << reason << "', got '" << msg << "'";
  return ::testing::AssertionSuccess();
}

}  // namespace i20::faults::testing
