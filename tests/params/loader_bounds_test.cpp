// SPDX-License-Identifier: GPL-2.0-or-later
// The database loader on hostile input (fuzz/regressions/param_db): every number is
// checked before it is used, every refusal is one ParamFileError line naming file and
// line, and nothing else escapes.
#include <gtest/gtest.h>

#include <string>

#include "params/param_db.hpp"

using namespace i20::params;

namespace {

std::string error_of(const std::string& yaml) {
  try {
    ParamDb::load_string(yaml, "bad.yaml");
  } catch (const ParamFileError& e) {
    return e.what();
  }
  return "(accepted)";
}

std::string overlay_error(const std::string& yaml) {
  ParamDb db = ParamDb::builtin();
  try {
    db.apply_overlay_string(yaml, "overlay.yaml");
  } catch (const ParamFileError& e) {
    return e.what();
  }
  return "(accepted)";
}

std::string entry_with(const std::string& width_and_sign) {
  return "parameters:\n  - name: A\n    space: ram\n    address: 0x10\n" + width_and_sign +
         "    access: rw\n    description: t\n    provenance: {source: t, confirmed_on: all}\n";
}

// width_range shifted by the width before read_fields checked it: 1 << 70 and 1 << -1
// are undefined behaviour (UBSan: shift exponent out of range).
TEST(ParamDbBounds, WidthIsCheckedBeforeItIsUsed) {
  EXPECT_EQ(error_of(entry_with("    width: 70\n    signed: false\n")),
            "bad.yaml:5: 'width' must be 8, 16 or 32 bits, not 70");
  EXPECT_EQ(error_of(entry_with("    width: 96\n    signed: true\n")),
            "bad.yaml:5: 'width' must be 8, 16 or 32 bits, not 96");
  EXPECT_EQ(error_of(entry_with("    width: 0\n    signed: true\n")),
            "bad.yaml:5: 'width' must be 8, 16 or 32 bits, not 0");
  EXPECT_EQ(error_of(entry_with("    width: -9223372036854775808\n    signed: true\n")),
            "bad.yaml:5: 'width' must be 8, 16 or 32 bits, not -9223372036854775808");
  EXPECT_EQ(overlay_error("parameters:\n  - name: NVMAXCURRENT\n    width: 64\n"),
            "overlay.yaml:3: 'width' must be 8, 16 or 32 bits, not 64")
      << "an overlay changing a width goes through the same check";
}

// Reader::integer negated what from_chars read after the sign: "--9223372036854775808"
// negated INT64_MIN, and "--5" was 5.
TEST(ParamDbBounds, IntegersHaveOneSignAndFitInt64) {
  EXPECT_EQ(error_of("schema: --9223372036854775808\nparameters: []\n"),
            "bad.yaml:1: 'schema' must be an integer, not '--9223372036854775808'");
  EXPECT_EQ(error_of("schema: --1\nparameters: []\n"), "bad.yaml:1: 'schema' must be an integer, not '--1'");
  EXPECT_EQ(error_of("schema: 0x-1\nparameters: []\n"),
            "bad.yaml:1: 'schema' must be an integer, not '0x-1'");
  EXPECT_EQ(error_of("schema: -9223372036854775808\nparameters: []\n"),
            "bad.yaml:1: unsupported schema version (this toolkit reads schema 1)")
      << "INT64_MIN itself is an integer";
  EXPECT_EQ(error_of("schema: 9223372036854775808\nparameters: []\n"),
            "bad.yaml:1: 'schema' is out of range for a 64-bit integer: '9223372036854775808'");
  EXPECT_EQ(error_of(entry_with("    width: 16\n    signed: false\n    max: --5\n")),
            "bad.yaml:7: 'max' must be an integer, not '--5'");
  EXPECT_EQ(overlay_error("swrevision: -0x-1\nparameters: []\n"),
            "overlay.yaml:1: 'swrevision' must be an integer, not '-0x-1'");
}

// yaml-cpp bounds its own recursion (DepthGuard); the loader turns it into one line.
TEST(ParamDbBounds, DeepNestingIsOneLineOfError) {
  const std::string deep = "parameters: " + std::string(5000, '[') + std::string(5000, ']') + "\n";
  const std::string err = error_of(deep);
  EXPECT_EQ(err.rfind("bad.yaml:1: not valid YAML: ", 0), 0u) << err;
  EXPECT_EQ(err.find('\n'), std::string::npos) << err;
  const std::string nested_map = "parameters:\n  - name: " + std::string(3000, '{') + "\n";
  EXPECT_EQ(error_of(nested_map).find('\n'), std::string::npos);
}

// yaml-cpp 0.7 cannot read past a stray ',' and its LoadAll then returns empty documents
// for ever (the fuzzer's timeout): the loader says where it stuck, and returns.
TEST(ParamDbBounds, AStrayCommaIsRefusedNotLoopedOn) {
  EXPECT_EQ(error_of("\n,\n"),
            "bad.yaml:2: not valid YAML: the parser cannot read past this line (a stray ',' or similar)");
  EXPECT_EQ(error_of("parameters: []\n,\n").rfind("bad.yaml:", 0), 0u);
  EXPECT_EQ(error_of("parameters: []\n---\n---\n"), error_of("parameters: []\n"))
      << "empty documents drop nothing";
}

}  // namespace
