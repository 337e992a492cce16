// SPDX-License-Identifier: GPL-2.0-or-later
// The linter on deliberately broken files (tests/linuxcnc/data): names reached through
// aliases, misspelt names, and statements halcmd itself refuses. Each finding must be on
// the line the file's comments say, with its rule; halcmd's refusals make the exit code 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "build_paths.hpp"
#include "hal_plans.hpp"
#include "linuxcnc/hal_generate.hpp"
#include "linuxcnc/hal_lint.hpp"

using namespace i20::linuxcnc;
namespace fs = std::filesystem;

namespace {

// The power-up delays the program writes (ops/core/timing.hpp).
using test::kProgramDelays;

std::string data_text(const std::string& name) {
  std::ifstream in(i20::test::source_dir() / "tests/linuxcnc/data" / name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

using Lines = std::set<int>;

// The lines of each rule's findings in `file`.
std::map<std::string, Lines> by_rule(const std::vector<LintFinding>& findings, const std::string& file) {
  std::map<std::string, Lines> out;
  for (const auto& f : findings)
    if (f.at.file == file) out[f.rule].insert(f.at.line);
  return out;
}

// "# RULE..." comments: the line after each names the rule that must be found on it.
std::map<std::string, Lines> announced(const std::string& text) {
  std::map<std::string, Lines> out;
  std::stringstream in(text);
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (line.rfind("# ", 0) != 0) continue;
    const auto rule = line.substr(2, line.find_first_of(":\n", 2) - 2);
    if (rule.find(' ') == std::string::npos && rule.find('-') != std::string::npos)
      out[rule].insert(number + 1);
  }
  return out;
}

std::string all(const std::vector<LintFinding>& findings) {
  std::string out;
  for (const auto& f : findings) out += to_string(f) + "\n";
  return out;
}

}  // namespace

TEST(HalLintBroken, EveryStatementHalcmdRefusesIsFoundOnItsLineAndExitsTwo) {
  const auto text = data_text("halcmd-refuses.hal");
  const auto findings = lint(read_hal(text, "refuses.hal"), {});
  const auto expected = announced(text);
  ASSERT_EQ(expected.size(), 8u) << "the file announces eight rules";
  EXPECT_EQ(by_rule(findings, "refuses.hal"), expected) << all(findings);
  for (const auto& f : findings) EXPECT_TRUE(f.refused_by_halcmd) << to_string(f);
  EXPECT_EQ(lint_exit_code(findings), 2);
}

TEST(HalLintBroken, AliasesAreResolvedForEveryRule) {
  const auto text = data_text("alias-8i20.hal");
  const auto findings = lint(read_hal(text, "alias.hal"), {});
  const auto expected = announced(text);
  EXPECT_EQ(by_rule(findings, "alias.hal"), expected) << all(findings);
  // The messages name the real pin and the alias the file wrote.
  for (const auto& f : findings) {
    if (f.rule == "second-lead") {
      EXPECT_NE(f.message.find("hm2_7i96s.0.8i20.0.0.angle"), std::string::npos) << f.message;
    }
    if (f.rule == "current-scaling") {
      EXPECT_NE(f.message.find("current-scalemax"), std::string::npos) << f.message;
    }
  }
  EXPECT_EQ(lint_exit_code(findings), 2) << "the angle on two signals";
}

TEST(HalLintBroken, AnAliasReachesOnlyWhatItNamesUntilUnaliased) {
  const std::string text =
      "loadrt bldc cfg=qh\n"
      "alias pin bldc.0.value v\n"
      "alias pin v w\n"             // a new alias of the same pin replaces the old one
      "net s1 pid.0.output => w\n"  // bldc.0.value
      "unalias pin w\n"
      "net s2 w\n";  // a pin named w again: not bldc.0.value
  const auto findings = lint(read_hal(text, "a.hal"), {});
  for (const auto& f : findings) EXPECT_NE(f.rule, "pin-on-two-signals") << to_string(f);
  const auto again = lint(read_hal(text + "net s3 bldc.0.value\n", "a.hal"), {});
  EXPECT_EQ(by_rule(again, "a.hal")["pin-on-two-signals"], (Lines{7})) << all(again);
}

TEST(HalLintBroken, MisspeltNamesAreFoundWithTheNameMeant) {
  const auto text = data_text("misspelt-8i20.hal");
  const auto findings = lint(read_hal(text, "misspelt.hal"), {});
  auto expected = announced(text);
  // The misspelt Hall pin leaves bldc.0.hall1 unconnected, and the misspelt fault pin leaves
  // the 8I20's faults reaching nothing.
  expected["bldc-input"] = {6};
  expected["faults-unconnected"] = {9};
  EXPECT_EQ(by_rule(findings, "misspelt.hal"), expected) << all(findings);
  std::map<int, std::string> fixes;
  for (const auto& f : findings)
    if (f.rule == "unknown-name") fixes[f.at.line] = f.fix;
  EXPECT_EQ(fixes[9], "write hm2_7i96s.0.8i20.0.0.angle");
  EXPECT_EQ(fixes[12], "write hm2_7i96s.0.8i20.0.0.fault.overcurrent");
  EXPECT_EQ(fixes[16], "write hm2_7i96s.0.encoder.00.rawcounts");
  EXPECT_EQ(fixes[18], "write bldc.0.hall1");
  EXPECT_EQ(fixes[22], "write pid.x.maxoutput");
  EXPECT_EQ(lint_exit_code(findings), 1) << "names: findings, not a refusal";
}

TEST(HalLintBroken, EveryNameHostmot2MakesForAnEightI20IsKnown) {
  const auto& names = HalNames::builtin();
  std::string text = "loadrt bldc cfg=qh\n";
  for (const auto& [name, object] : names.i20_objects())
    text += (object.settable() ? "setp hm2_7i96s.0.8i20.0.0." + name + " 1\n"
                               : "net s-" + name + " hm2_7i96s.0.8i20.0.0." + name + "\n");
  const auto findings = lint(read_hal(text, "all.hal"), {});
  for (const auto& f : findings) EXPECT_NE(f.rule, "unknown-name") << to_string(f);
  // sserial.h's 8I20 globals: the integrator limits, and no feed-forward gains.
  for (const char* global : {"nvkqihi", "nvkqilo", "nvkdihi", "nvkdilo", "nvkqil", "nvkdil"})
    EXPECT_EQ(names.i20_objects().count(global), 1u) << global;
  for (const char* gone : {"nvkqff", "nvkdff"}) EXPECT_EQ(names.i20_objects().count(gone), 0u) << gone;
  // Inputs have their three params, outputs a full scale only.
  EXPECT_EQ(names.i20_objects().count("current-minlim"), 1u);
  EXPECT_EQ(names.i20_objects().count("bus-voltage-scalemax"), 1u);
  EXPECT_EQ(names.i20_objects().count("bus-voltage-maxlim"), 0u);
}

// `i20 hal`'s file and `i20 commission -o`'s fragment are each clean, and halcmd refuses
// them sourced together: bldc loaded twice, its pins netted twice, its function added twice.
TEST(HalLintBroken, TheGeneratedFileWithACommissionFragmentIsRefused) {
  const HalPlan p = test::hall_encoder_plan(1);
  auto statements = read_hal(generate_hal(p, kProgramDelays), "axis.hal");
  const auto fragment_text = data_text("commission-fragment.hal");
  const auto fragment = read_hal(fragment_text, "x-axis.hal");
  EXPECT_EQ(lint_exit_code(lint(statements, {p.max_current, p.pattern})), 0);
  statements.insert(statements.end(), fragment.begin(), fragment.end());
  const auto findings = lint(statements, {p.max_current, p.pattern});
  const auto rules = by_rule(findings, "x-axis.hal");
  EXPECT_EQ(rules.at("module-loaded-twice"), (Lines{5})) << all(findings);
  EXPECT_EQ(rules.at("function-added-twice"), (Lines{17})) << all(findings);
  // Every net of the fragment names a pin the generated file has netted already.
  EXPECT_EQ(rules.at("pin-on-two-signals"), (Lines{9, 10, 11, 12, 14, 16})) << all(findings);
  EXPECT_EQ(lint_exit_code(findings), 2);
}

TEST(HalLintBroken, ExitCodes) {
  EXPECT_EQ(lint_exit_code({}), 0);
  // Built in place: GCC 12 at -O3 warns maybe-uninitialized (falsely) on a braced copy.
  std::vector<LintFinding> findings(1);
  findings[0].at = {"a.hal", 1};
  findings[0].rule = "unknown-name";
  EXPECT_EQ(lint_exit_code(findings), 1);
  findings.push_back(findings[0]);
  findings[1].refused_by_halcmd = true;
  EXPECT_EQ(lint_exit_code(findings), 2);
}
