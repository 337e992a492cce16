// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 33: nothing claimed that did not happen. Each case as a new user or a tired
// technician meets it, judged by the virtual card's own state and by what is on disk:
//  1. `profile undo FILE` of another unit's backup is refused (exit 3, nothing written);
//  2. output that does not land (a full disk, /dev/full) is exit 6, and leaves no file;
//  3. a full backup disk leaves no 0-byte backup, and undo --last passes over a broken one;
//  4. a second YAML document is refused, not dropped;
//  5. `watch | head -1` ends, and frees the port;
//  7. a leading zero is refused as ambiguous; control characters never reach the terminal.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include "cli_profile_util.hpp"
#include "small_disk.hpp"

using namespace i20::test;
namespace fs = std::filesystem;

namespace {

constexpr const char* kUnitA = "0x00012345";
constexpr const char* kUnitB = "0x00055555";

std::vector<std::string> card_args(const char* unit) {
  std::vector<std::string> args = kLine120Bus;
  args.insert(args.end(), {"--unit-number", unit});
  return args;
}

// A shell command line's exit status (its output is the caller's business).
int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

std::string i20_path() {
  return program("i20").string();
}

class Honesty : public ::testing::Test {
 protected:
  TempDir dir;
};

}  // namespace

// 1. A backup is of one unit: restoring it onto another is refused before any write,
// naming both units; --force restores it, saying what it overrode.
TEST_F(Honesty, UndoOfAnotherUnitsBackupIsRefusedAndWritesNothing) {
  SimProcess a{card_args(kUnitA)};
  const auto backups = (dir / "backups").string();
  ASSERT_EQ(i20_on(a.port(), {"profile", "apply", "line-120v", "--backup-dir", backups}).exit_code, 0);
  const auto saved = backups_in(dir / "backups");
  ASSERT_EQ(saved.size(), 1u);
  EXPECT_NE(slurp_file(saved.front()).find("unit: 0x00012345"), std::string::npos)
      << "the backup records its origin: " << slurp_file(saved.front());

  SimProcess b{card_args(kUnitB)};
  const auto before = sim_value(b, "NVMAXCURRENT");
  auto r = i20_on(b.port(), {"profile", "undo", saved.front().string(), "--backup-dir", backups});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.err.find("read from unit 0x00012345, not unit 0x00055555"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--force"), std::string::npos) << "names the override: " << r.err;
  EXPECT_EQ(r.out.find("APPLIED"), std::string::npos) << r.out;
  EXPECT_EQ(eeprom_writes(b.trace()), 0u) << "nothing was written: " << b.trace();
  EXPECT_EQ(sim_value(b, "NVMAXCURRENT"), before);

  // A backup renamed so its name no longer says the unit: the origin block still does.
  const auto renamed = dir / "axis-x.yaml";
  fs::copy_file(saved.front(), renamed);
  EXPECT_EQ(i20_on(b.port(), {"profile", "undo", renamed.string(), "--backup-dir", backups}).exit_code, 3);

  // Card B set up differently, so the forced restore has something to write.
  ASSERT_EQ(i20_on(b.port(), {"profile", "apply", "line-120v"}).exit_code, 0);
  const auto writes = eeprom_writes(b.trace());
  r = i20_on(b.port(), {"profile", "undo", saved.front().string(), "--backup-dir", backups, "--force"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("restoring anyway"), std::string::npos) << r.err;
  EXPECT_GT(eeprom_writes(b.trace()), writes);
}

// A backup with no origin (written by hand, or by an older version, renamed) says nothing
// of its card: refused unless forced, never assumed to be this card's.
TEST_F(Honesty, UndoOfABackupThatNamesNoUnitIsRefused) {
  SimProcess b{card_args(kUnitB)};
  const auto file = write_file(dir / "old.yaml", "name: old\nparameters:\n  NVKQP: 100\n");
  const auto r = i20_on(b.port(), {"profile", "undo", file, "--backup-dir", dir.path().string()});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.err.find("does not say which 8I20"), std::string::npos) << r.err;
  EXPECT_EQ(eeprom_writes(b.trace()), 0u);
}

// 2. stdout that does not take the output: exit 6 and a message, not a success.
TEST_F(Honesty, OutputToAFullDeviceIsExitSix) {
  const std::string i20 = quoted(i20_path()) + " --no-user-params --sim ";
  const std::string err = quoted((dir / "err").string());
  for (const std::string& command :
       {i20 + "get NVKQP", i20 + "dump", i20 + "report", i20 + "profile save -",
        i20 + "hal --max-current 12A --cfg h --pattern 25 --halls "
              "hm2_7i96s.0.inm.00.input-00,hm2_7i96s.0.inm.00.input-01,hm2_7i96s.0.inm.00.input-02",
        // The console's URL carries its only token: unseen, it must not serve (timeout: 124).
        "timeout 20 " + i20 + "console --no-browser"}) {
    EXPECT_EQ(shell(command + " > /dev/full 2> " + err), 6) << command;
    const std::string said = slurp_file(dir / "err");
    const auto first = said.find("standard output was not written in full");
    EXPECT_NE(first, std::string::npos) << command << ": " << said;
    EXPECT_EQ(said.find("standard output was not written in full", first + 1), std::string::npos)
        << "said once: " << command << ": " << said;
  }
  const std::string rpd = quoted(program("rpd").string()) + " --sim NVKQP";
  EXPECT_EQ(shell(rpd + " > /dev/full 2> " + err), 6);
  EXPECT_EQ(shell(i20 + "get NVKQP > /dev/null 2> " + err), 0) << "a sink that takes it is fine";
}

// 2. Files on a full disk: exit 6, and no partial (0-byte) file under the name.
TEST_F(Honesty, FilesOnAFullDiskAreExitSixAndLeaveNoFile) {
  SmallDisk disk(dir / "small", 64);
  if (!disk.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root";
  disk.fill();
  const std::string i20 = quoted(i20_path()) + " --no-user-params --sim ";
  const auto at = [&](const std::string& name) { return (disk.path() / name).string(); };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"profile save " + quoted(at("axis.yaml")), "axis.yaml"},
      {"report -o " + quoted(at("report.yaml")), "report.yaml"},
      {"profile export line-120v --hal -o " + quoted(at("axis.hal")), "axis.hal"},
      {"tune -R 0.6ohm -L 1.75mH --max-current 8A --bus 320V -o " + quoted(at("tune.yaml")), "tune.yaml"},
  };
  for (const auto& [command, file] : cases) {
    const int code = shell(i20 + command + " > /dev/null 2> " + quoted((dir / "err").string()));
    EXPECT_EQ(code, 6) << command << ": " << slurp_file(dir / "err");
    EXPECT_FALSE(fs::exists(disk.path() / file)) << command << " left a partial file";
  }
  // A live log: the watch ends (exit 6) at the first row that does not land.
  const int code = shell(i20 + "watch --interval 50 --count 50 --log " + quoted(at("w.csv")) +
                         " > /dev/null 2> " + quoted((dir / "err").string()));
  EXPECT_EQ(code, 6) << slurp_file(dir / "err");
  EXPECT_NE(slurp_file(dir / "err").find("cannot write the log file"), std::string::npos)
      << slurp_file(dir / "err");
  EXPECT_FALSE(fs::exists(disk.path() / "w.csv")) << "not even the header landed: no empty log left";
}

// 3. A full backup disk: nothing written to the card, no 0-byte backup left; after space is
// freed, undo --last finds the older valid backup (and passes over a broken one, saying so).
TEST_F(Honesty, AFullBackupDiskLeavesNoBrokenBackupAndUndoStillWorks) {
  SmallDisk disk(dir / "backups", 64);
  if (!disk.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root";
  const auto backups = disk.path().string();
  SimProcess card{card_args(kUnitA)};
  ASSERT_EQ(i20_on(card.port(), {"profile", "apply", "line-120v", "--backup-dir", backups}).exit_code, 0);
  ASSERT_EQ(backups_in(disk.path()).size(), 1u);
  ASSERT_EQ(i20_on(card.port(), {"set", "NVKQP=77"}).exit_code, 0);

  disk.fill();
  const auto writes = eeprom_writes(card.trace());
  const auto kqp = write_file(dir / "kqp.yaml", "name: kqp\nparameters:\n  NVKQP: 90\n");
  auto r = i20_on(card.port(), {"profile", "apply", kqp, "--backup-dir", backups});
  EXPECT_EQ(r.exit_code, 6) << r.out << r.err;
  EXPECT_NE(r.out.find("nothing was written"), std::string::npos) << r.out;
  EXPECT_EQ(eeprom_writes(card.trace()), writes) << "no write without a backup";
  EXPECT_EQ(backups_in(disk.path()).size(), 1u) << "no 0-byte backup left behind";

  disk.free_space();
  // An older version's leftover: a 0-byte newest backup of this unit.
  write_file(disk.path() / "i20-backup-99991231-235959-kqp-unit00012345.yaml", "");
  r = i20_on(card.port(), {"profile", "undo", "--last", "--backup-dir", backups});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("passed over"), std::string::npos) << "the broken one is named: " << r.err;
  EXPECT_EQ(sim_value(card, "NVBRAKEONV"), 36000) << "the valid backup was restored";
}

// 4. A second YAML document is not silently dropped, even a broken one.
TEST_F(Honesty, AProfileWithTwoDocumentsIsRefused) {
  SimProcess card{kLine120Bus};
  for (const std::string second : {"name: second\nparameters:\n  NVKQP: 90\n", "name: [broken\n"}) {
    const auto file = write_file(dir / "two.yaml", "name: first\nparameters:\n  NVKQP: 100\n---\n" + second);
    const auto r = i20_on(card.port(), {"profile", "apply", file});
    EXPECT_EQ(r.exit_code, 2) << second << r.out << r.err;
    EXPECT_EQ(r.out.find("APPLIED"), std::string::npos) << r.out;
  }
  EXPECT_EQ(card.writes_seen(), 0u);
  // A stray `---` at the end holds nothing to drop.
  const auto file = write_file(dir / "one.yaml", "name: first\nparameters:\n  NVKQP: 100\n---\n");
  EXPECT_EQ(i20_on(card.port(), {"profile", "validate", file}).exit_code, 0);
}

// 5. A watch whose reader went away ends, and the port is free for the next command.
TEST_F(Honesty, WatchEndsWhenItsReaderGoesAway) {
  SimProcess card;
  const auto start = std::chrono::steady_clock::now();
  const int code = shell("timeout 20 bash -c " +
                         quoted(quoted(i20_path()) + " --no-user-params --port " + card.port() +
                                " watch --plain --interval 50 | head -1 > /dev/null; exit ${PIPESTATUS[0]}"));
  EXPECT_EQ(code, 6) << "124 would be timeout(1) killing a watch that never ended";
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  const auto r = i20_on(card.port(), {"set", "NVKQP=77"});
  EXPECT_EQ(r.exit_code, 0) << "the port lock was released: " << r.err;
}

// 7. "017" is 15 to YAML 1.1 tools and C, 17 to a decimal parser: refused, naming both.
TEST_F(Honesty, ALeadingZeroIsRefusedAsAmbiguous) {
  SimProcess card{kLine120Bus};
  auto r = i20_on(card.port(), {"set", "NVKQP=017"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("octal 15"), std::string::npos) << r.err;
  const auto file = write_file(dir / "octal.yaml", "name: octal\nparameters:\n  NVKQP: 017\n");
  r = i20_on(card.port(), {"profile", "apply", file});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_EQ(card.writes_seen(), 0u);
  EXPECT_EQ(i20_on(card.port(), {"set", "NVKQP=0x11"}).exit_code, 0) << "hexadecimal stays fine";
}

// 7. A control character from a file or an argument never reaches the terminal raw.
TEST_F(Honesty, ControlCharactersAreNeverPrintedRaw) {
  SimProcess card{kLine120Bus};
  const auto file = write_file(dir / "esc.yaml", "name: \"clear\\e[2J\"\nparameters:\n  NVKQP: 100\n");
  auto r = i20_on(card.port(), {"profile", "apply", file});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("\\x1B"), std::string::npos) << r.err;
  EXPECT_EQ((r.out + r.err).find('\x1b'), std::string::npos);
  r = i20_on(card.port(), {"set", "NVKQP=1\x1b[2J"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ((r.out + r.err).find('\x1b'), std::string::npos) << r.err;
  EXPECT_EQ(card.writes_seen(), 0u);
}
