// SPDX-License-Identifier: GPL-2.0-or-later
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include "harness.hpp"

using namespace i20::test;

namespace {

const std::vector<std::string> kGood{
    "hal",  "--max-current", "12A",           "--pattern", "17", "--poles", "8", "--counts-per-rev",
    "4000", "--halls",       "a.in,b.in,c.in"};

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

void write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(HalCli, WritesAFileThatItsOwnLintPasses) {
  TempDir dir;
  const auto file = dir / "axis.hal";
  const auto made = run("i20", with(kGood, {"-o", file.string()}));
  ASSERT_EQ(made.exit_code, 0) << made.err;
  EXPECT_NE(read(file).find("net j0-rotor-angle bldc.0.rotor-angle => hm2_7i96s.0.8i20.0.0.angle"),
            std::string::npos);
  const auto lint = run("i20", {"hal", "lint", "--max-current", "12A", "--pattern", "17", file.string()});
  EXPECT_EQ(lint.exit_code, 0) << lint.out << lint.err;
  EXPECT_EQ(lint.out, "");
}

// --notch: a biquad after the pid, its coefficients from the INI `i20 pid --notch` writes; the
// file says how it was asked for, and its own lint passes it.
TEST(HalCli, TheNotchIsWrittenAndLintsClean) {
  TempDir dir;
  const auto file = dir / "axis.hal";
  const auto made = run("i20", with(kGood, {"--notch", "-o", file.string()}));
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const std::string text = read(file);
  for (const char* line :
       {"loadrt biquad names=i20-notch-0\n", "net j0-torque-raw pid.0.output => i20-notch-0.in\n",
        "net j0-torque i20-notch-0.out => bldc.0.value\n", "setp i20-notch-0.n0 [JOINT_0]NOTCH_N0\n",
        " --notch\n"})
    EXPECT_NE(text.find(line), std::string::npos) << line;
  const auto lint = run("i20", {"hal", "lint", "--max-current", "12A", "--pattern", "17", file.string()});
  EXPECT_EQ(lint.exit_code, 0) << lint.out << lint.err;
}

// hal lint --ini: the notch's keys must be in the INI when the file runs the notch (halcmd
// stops at a missing one: exit 2), and a notch in the INI that the file does not run is said
// (exit 1); the file with the INI it reads is clean.
TEST(HalCli, LintHoldsTheFilesAgainstTheIni) {
  TempDir dir;
  const auto notched = dir / "notched.hal", plain = dir / "plain.hal";
  ASSERT_EQ(run("i20", with(kGood, {"--notch", "-o", notched.string()})).exit_code, 0);
  ASSERT_EQ(run("i20", with(kGood, {"-o", plain.string()})).exit_code, 0);
  const std::string base =
      "[KINS]\nKINEMATICS = trivkins\nJOINTS = 1\n[EMCMOT]\nEMCMOT = motmod\nSERVO_PERIOD = 1000000\n"
      "[JOINT_0]\nENCODER_SCALE = 800\nP = 1\nI = 0\nD = 0\nFF0 = 0\nFF1 = 0\nFF2 = 0\nBIAS = 0\nDEADBAND = "
      "0\n";
  const auto with_notch = dir / "notch.ini", without = dir / "plain.ini";
  write(with_notch,
        base + "NOTCH_N0 = 0.8\nNOTCH_N1 = -0.7\nNOTCH_N2 = 0.8\nNOTCH_D1 = -0.7\nNOTCH_D2 = 0.63\n");
  write(without, base);
  const auto lint = [](const std::filesystem::path& hal, const std::filesystem::path& ini) {
    return run("i20", {"hal", "lint", "--max-current", "12A", "--pattern", "17", "--ini", ini.string(),
                       hal.string()});
  };
  EXPECT_EQ(lint(notched, with_notch).exit_code, 0) << lint(notched, with_notch).out;
  EXPECT_EQ(lint(plain, without).exit_code, 0) << lint(plain, without).out;
  const auto missing = lint(notched, without);
  EXPECT_EQ(missing.exit_code, 2) << missing.out << missing.err;
  EXPECT_NE(missing.out.find("[JOINT_0]NOTCH_N0 is not in " + without.string()), std::string::npos)
      << missing.out;
  const auto not_run = lint(plain, with_notch);
  EXPECT_EQ(not_run.exit_code, 1) << not_run.out << not_run.err;
  EXPECT_NE(not_run.out.find("[JOINT_0] has a notch"), std::string::npos) << not_run.out;
}

TEST(HalCli, RefusesToReplaceAFileWithoutOverwrite) {
  TempDir dir;
  const auto file = dir / "mine.hal";
  write(file, "# the user's own file\n");
  const auto refused = run("i20", with(kGood, {"-o", file.string()}));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("exists; pass --overwrite"), std::string::npos) << refused.err;
  EXPECT_EQ(read(file), "# the user's own file\n");
  EXPECT_EQ(run("i20", with(kGood, {"-o", file.string(), "--overwrite"})).exit_code, 0);
  EXPECT_NE(read(file).find("loadrt bldc cfg=qh"), std::string::npos);
  // No temporary file is left beside it.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(HalCli, BadOptionsFailWithOneLineAndExit2) {
  for (const auto& extra : std::vector<std::vector<std::string>>{{"--cfg", "qi"},
                                                                 {"--board", "5i25"},
                                                                 {"--encoder-offset", "3"},
                                                                 {"--axes", "0"},
                                                                 {"--board-ip", "x"}}) {
    const auto r = run("i20", with(kGood, extra));
    EXPECT_EQ(r.exit_code, 2) << extra[0];
    EXPECT_EQ(r.out, "") << extra[0];
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  const auto no_current = run("i20", {"hal", "--pattern", "17", "--poles", "8", "--counts-per-rev", "4000",
                                      "--halls", "a.in,b.in,c.in"});
  EXPECT_EQ(no_current.exit_code, 2);
  EXPECT_NE(no_current.err.find("--max-current (or --profile) is required"), std::string::npos)
      << no_current.err;
  EXPECT_EQ(run("i20", with(kGood, {"--max-current", "12 furlongs"})).exit_code, 2);
  // A bare number is refused, as by every other command that takes a current: amps or mA?
  auto bare_args = kGood;
  *std::find(bare_args.begin(), bare_args.end(), std::string("12A")) = "10";
  const auto bare = run("i20", bare_args);
  EXPECT_EQ(bare.exit_code, 2) << bare.err;
  EXPECT_NE(bare.err.find("give the unit, e.g. 10A"), std::string::npos) << bare.err;
}

TEST(HalCli, LintExitCodes) {
  TempDir dir;
  const auto clean = dir / "clean.hal";
  write(clean,
        "loadrt bldc cfg=qh\nnet a bldc.0.rotor-angle hm2_7i96s.0.8i20.0.0.angle\n"
        "net f hm2_7i96s.0.8i20.0.0.fault.watchdog x.in\nnet r enc.rawcounts bldc.0.rawcounts\n"
        "net h1 p.a bldc.0.hall1\nnet h2 p.b bldc.0.hall2\nnet h3 p.c bldc.0.hall3\n");
  EXPECT_EQ(run("i20", {"hal", "lint", clean.string()}).exit_code, 0);
  const auto old = dir / "old.hal";
  write(old, "# old\nsetp hm2_5i20.0.8i20.0.0.max_current 30.0\n");
  const auto findings = run("i20", {"hal", "lint", old.string()});
  EXPECT_EQ(findings.exit_code, 1);
  EXPECT_EQ(findings.out.rfind(old.string() + ":2: error: hm2_5i20.0.8i20.0.0.max_current", 0), 0u)
      << findings.out;
  const auto json = run("i20", {"--json", "hal", "lint", old.string()});
  EXPECT_EQ(json.exit_code, 1);
  EXPECT_NE(json.out.find("\"obsolete-8i20-name\""), std::string::npos) << json.out;
  const auto broken = dir / "broken.hal";
  write(broken, "setp a.b \"1\nfoo\n");
  const auto syntax = run("i20", {"hal", "lint", broken.string()});
  EXPECT_EQ(syntax.exit_code, 2);
  EXPECT_NE(syntax.err.find(broken.string() + ":1: unterminated quoted string"), std::string::npos)
      << syntax.err;
  EXPECT_EQ(run("i20", {"hal", "lint", (dir / "missing.hal").string()}).exit_code, 2);
}

TEST(HalCli, MaxcurrentFromAMotorProfile) {
  // profiles/line-120v.yaml sets NVMAXCURRENT 12 A.
  const auto r = run("i20", {"hal", "--profile", "line-120v", "--pattern", "17", "--poles", "8",
                             "--counts-per-rev", "4000", "--halls", "a.in,b.in,c.in"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("setp pid.0.maxoutput 12 "), std::string::npos);
  EXPECT_EQ(run("i20", with(kGood, {"--profile", "line-120v"})).exit_code, 2);  // not both
  TempDir dir;
  const auto hal = dir / "x.hal";
  write(hal,
        "loadrt pid num_chan=1\nsetp pid.0.maxoutput 15\nnet c pid.0.output hm2_7i96s.0.8i20.0.0.current\n");
  const auto lint = run("i20", {"hal", "lint", "--profile", "line-120v", hal.string()});
  EXPECT_EQ(lint.exit_code, 1);
  EXPECT_NE(
      lint.out.find(hal.string() +
                    ":2: warning: hm2_7i96s.0.8i20.0.0.current is fed from pid.0 whose maxoutput is 15 A"),
      std::string::npos)
      << lint.out;
}

// --overwrite replaces a regular file only: a device node, a FIFO or a symbolic link stays what
// it is (as root, `-o /dev/null --overwrite` once replaced /dev/null with a file). A FIFO stands
// in for the device here; both are refused by the same check. So does `watch --log`.
TEST(HalCli, NeverWritesOverAnythingButARegularFile) {
  TempDir dir;
  const auto fifo = dir / "a-fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto refused = run("i20", with(kGood, {"-o", fifo.string(), "--overwrite"}));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("is a FIFO, not a regular file"), std::string::npos) << refused.err;
  EXPECT_TRUE(std::filesystem::is_fifo(std::filesystem::symlink_status(fifo)));

  const auto target = dir / "target.hal";
  write(target, "# the user's own file\n");
  const auto link = dir / "link.hal";
  std::filesystem::create_symlink(target, link);
  refused = run("i20", with(kGood, {"-o", link.string(), "--overwrite"}));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("is a symbolic link, not a regular file"), std::string::npos) << refused.err;
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(read(target), "# the user's own file\n");

  refused = run("i20", {"--sim", "watch", "--log", fifo.string(), "--duration", "1"});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("it is a FIFO, not a regular file"), std::string::npos) << refused.err;
  EXPECT_TRUE(std::filesystem::is_fifo(std::filesystem::symlink_status(fifo)));
}
