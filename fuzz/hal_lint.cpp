// SPDX-License-Identifier: GPL-2.0-or-later
// The HAL reader (lib/linuxcnc/hal_file) and the linter on what it accepts: the reader
// rejects only with its own syntax error, and the linter never throws on a file the reader
// took, with or without the commissioning facts. Every finding points at a line of the file.
#include "linuxcnc/hal_lint.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace i20::linuxcnc;
  const std::string text(i20::fuzz::text_of(data, size));
  std::optional<std::vector<Statement>> statements;
  i20::fuzz::expect_only_toolkit_errors([&] { statements = read_hal(text, "fuzz.hal"); });
  if (!statements) return 0;
  const int lines = 1 + static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  i20::fuzz::expect_no_exception([&] {
    for (const LintOptions& options : {LintOptions{}, LintOptions{12.0, 17}})
      for (const auto& f : lint(*statements, options))
        i20::fuzz::require(f.at.file == "fuzz.hal" && f.at.line >= 1 && f.at.line <= lines,
                           "a finding points at a line of the file");
  });
  return 0;
}
