// SPDX-License-Identifier: GPL-2.0-or-later
// The linter on files nobody here wrote: LinuxCNC's own Smithy sample configs as Debian's
// linuxcnc-uspace installs them, and a PnCconf-style file written from the documented
// facts (tests/linuxcnc/data/pncconf-style-8i20.hal).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "build_paths.hpp"
#include "linuxcnc/hal_lint.hpp"

using namespace i20::linuxcnc;
namespace fs = std::filesystem;

namespace {

const fs::path kSmithy = "/usr/share/doc/linuxcnc/examples/sample-configs/by_machine/smithy";

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string line_of(const std::string& text, int line) {
  std::stringstream in(text);
  std::string out;
  for (int i = 0; i < line && std::getline(in, out); ++i) {
  }
  return out;
}

std::vector<Statement> read_all(const std::vector<fs::path>& files) {
  std::vector<Statement> all;
  for (const auto& f : files) {
    auto s = read_hal(read_text(f), f.filename().string());
    all.insert(all.end(), s.begin(), s.end());
  }
  return all;
}

// (file, line) of each finding of `rule`.
std::set<std::pair<std::string, int>> where(const std::vector<LintFinding>& findings,
                                            const std::string& rule) {
  std::set<std::pair<std::string, int>> out;
  for (const auto& f : findings)
    if (f.rule == rule) out.insert({f.at.file, f.at.line});
  return out;
}

#define SKIP_WITHOUT_SMITHY()                                                                     \
  if (!fs::exists(kSmithy / "1240combined.hal"))                                                  \
  GTEST_SKIP() << "LinuxCNC's sample configs are not installed (Debian package linuxcnc-uspace; " \
                  "scripts/install-deps --ci installs it)"

}  // namespace

TEST(HalLintFiles, Smithy1240CombinedUsesTheRemovedMaxCurrentAndAmpEnable) {
  SKIP_WITHOUT_SMITHY();
  const auto main_file = kSmithy / "1240combined.hal";
  const auto findings = lint(read_all({main_file}), {});
  const std::set<std::pair<std::string, int>> expected{{"1240combined.hal", 85}, {"1240combined.hal", 184}};
  EXPECT_EQ(where(findings, "obsolete-8i20-name"), expected);
  // The lines are the ones that say so in the installed file.
  const auto text = read_text(main_file);
  EXPECT_NE(line_of(text, 85).find("8i20.0.0.max_current 30.0"), std::string::npos);
  EXPECT_NE(line_of(text, 184).find("8i20.0.0.amp_enable"), std::string::npos);
  // It feeds rotor-angle (with lead-angle 0), so no second lead; its faults reach nothing.
  EXPECT_TRUE(where(findings, "second-lead").empty());
  EXPECT_EQ(where(findings, "faults-unconnected"),
            (std::set<std::pair<std::string, int>>{{"1240combined.hal", 84}}));
  for (const auto& f : findings)
    EXPECT_EQ(f.severity == LintSeverity::Error, f.rule == "obsolete-8i20-name") << to_string(f);
}

TEST(HalLintFiles, SmithyPostguiReadsTheRemovedStatusPins) {
  SKIP_WITHOUT_SMITHY();
  // LinuxCNC runs HALFILE, then POSTGUI_HALFILE: one configuration.
  const auto findings = lint(read_all({kSmithy / "1240combined.hal", kSmithy / "8i20postgui.hal"}), {});
  std::set<std::pair<std::string, int>> expected{{"1240combined.hal", 85}, {"1240combined.hal", 184}};
  for (int line = 21; line <= 25; ++line)
    expected.insert({"8i20postgui.hal", line});  // comms fault status temp voltage
  EXPECT_EQ(where(findings, "obsolete-8i20-name"), expected);
  const auto postgui = read_text(kSmithy / "8i20postgui.hal");
  for (const char* old : {"comms", "fault", "status", "temp", "voltage"})
    EXPECT_NE(postgui.find(std::string("8i20.0.0.") + old + " "), std::string::npos) << old;
}

TEST(HalLintFiles, EverySmithyHalFileReadsAndEveryEightI20OneHasFindings) {
  SKIP_WITHOUT_SMITHY();
  int with_8i20 = 0;
  for (const auto& entry : fs::directory_iterator(kSmithy)) {
    if (entry.path().extension() != ".hal") continue;
    std::vector<Statement> statements;
    ASSERT_NO_THROW(statements = read_hal(read_text(entry.path()), entry.path().filename().string()))
        << entry.path();
    const auto findings = lint(statements, {});
    if (read_text(entry.path()).find(".8i20.") == std::string::npos) continue;
    ++with_8i20;
    EXPECT_FALSE(where(findings, "obsolete-8i20-name").empty()) << entry.path();
  }
  EXPECT_EQ(with_8i20, 3);  // 1240combined, 1240combined_4axis, 8i20postgui
}

TEST(HalLintFiles, EveryPnCconfMistakeIsFoundOnItsLine) {
  const fs::path file = i20::test::source_dir() / "tests/linuxcnc/data/pncconf-style-8i20.hal";
  const auto text = read_text(file);
  const auto findings = lint(read_hal(text, "pncconf.hal"), {});
  using Lines = std::set<std::pair<std::string, int>>;
  const auto at = [](std::initializer_list<int> lines) {
    Lines out;
    for (int l : lines) out.insert({"pncconf.hal", l});
    return out;
  };
  // 1. max_current and amp_enable were removed in 2012.
  EXPECT_EQ(where(findings, "obsolete-8i20-name"), at({66, 69}));
  // 2. The prefix's trailing dot: "..".
  EXPECT_EQ(where(findings, "malformed-name"), at({66, 67, 68, 69}));
  // 3. phase-angle into the 8I20's angle (Hall-only bldc: a fixed quarter-turn lead).
  EXPECT_EQ(where(findings, "second-lead"), at({67}));
  // 4. bldc pins and params that cfg=h does not create.
  EXPECT_EQ(where(findings, "bldc-cfg"), at({54, 55, 57, 58, 62, 63}));
  // 5. initvalue printed with %d.
  EXPECT_EQ(where(findings, "initvalue-zero"), at({54}));
  // 8. Nothing drives the pid's command or enable from the joint.
  EXPECT_EQ(where(findings, "pid-input"), at({35, 36}));
  // And no fault pin of the 8I20 goes anywhere.
  EXPECT_EQ(where(findings, "faults-unconnected"), at({66}));
  // The lines are what the comments say they are.
  EXPECT_NE(line_of(text, 54).find("initvalue          0"), std::string::npos);
  EXPECT_NE(line_of(text, 67).find("..angle"), std::string::npos);
  EXPECT_NE(line_of(text, 36).find("pid.x.command"), std::string::npos);
}

TEST(HalLintFiles, EveryInstalledSampleConfigReadsButTheOneHalcmdAlsoRejects) {
  const fs::path samples = kSmithy.parent_path().parent_path();
  SKIP_WITHOUT_SMITHY();
  int read = 0;
  std::vector<std::string> rejected;
  for (const auto& entry : fs::recursive_directory_iterator(samples)) {
    if (entry.path().extension() != ".hal") continue;
    try {
      read_hal(read_text(entry.path()), entry.path().filename().string());
      ++read;
    } catch (const HalSyntaxError& e) {
      rejected.push_back(e.what());
    }
  }
  EXPECT_GT(read, 300);
  // LinuxCNC 2.9's halrun rejects this one too: a comment wrapped onto a line of its own
  // that opens a quote.
  EXPECT_EQ(rejected, std::vector<std::string>{"woodpecker.hal:16: unterminated quoted string"});
}
