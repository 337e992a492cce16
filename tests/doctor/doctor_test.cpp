// SPDX-License-Identifier: GPL-2.0-or-later
// i20 doctor's matcher on LinuxCNC's own output. tests/doctor/data/halrun-*.txt were
// captured from LinuxCNC 2.9's halrun with hm2_eth against the virtual 7I96S (i20sim in a
// network namespace, the rig of tests/linuxcnc_axis), each with one cause injected; the other
// lines below are LinuxCNC's wording from its sources (sserial.c, hostmot2.c, hm2_eth.c,
// watchdog.c, uspace_rtapi_app.cc; docs/field-messages.md names them).
#include "ops/doctor/doctor.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "build_paths.hpp"

namespace D = i20::doctor;

namespace {

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  EXPECT_TRUE(in) << p;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

D::Diagnosis of_capture(const std::string& name) {
  const auto path = i20::test::source_dir() / "tests/doctor/data" / ("halrun-" + name + ".txt");
  return D::diagnose(D::split_lines(read(path), name));
}

D::Diagnosis of_text(const std::string& text) {
  return D::diagnose(D::split_lines(text, "log"));
}

const D::Finding* find(const D::Diagnosis& d, const std::string& id) {
  for (const auto& f : d.findings)
    if (f.id == id) return &f;
  return nullptr;
}

std::vector<std::string> ids(const D::Diagnosis& d) {
  std::vector<std::string> out;
  for (const auto& f : d.findings) out.push_back(f.id);
  return out;
}

::testing::AssertionResult names(const D::Diagnosis& d, const std::string& id) {
  if (find(d, id)) return ::testing::AssertionSuccess();
  std::string all;
  for (const auto& f : d.findings) all += " " + f.id;
  return ::testing::AssertionFailure() << "no finding " << id << "; found:" << all;
}

}  // namespace

TEST(DoctorBook, LoadsAndEveryFindingCitesASectionOfTheDocs) {
  const auto& book = D::MessageBook::builtin();
  ASSERT_GT(book.rules().size(), 20u);
  const std::string doc = read(i20::test::source_dir() / "docs/field-messages.md");
  // GitHub's anchors: the heading lower-cased, spaces to '-', other punctuation dropped.
  std::set<std::string> anchors;
  std::istringstream lines(doc);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("## ", 0) != 0 && line.rfind("### ", 0) != 0) continue;
    std::string anchor;
    for (char c : line.substr(line.find(' ') + 1)) {
      if (std::isalnum(static_cast<unsigned char>(c)))
        anchor += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      else if (c == ' ' || c == '-')
        anchor += '-';
      else if (c == '_')
        anchor += '_';
    }
    anchors.insert(anchor);
  }
  for (const auto& rule : book.rules()) {
    if (rule.known) continue;
    const auto hash = rule.docs.find('#');
    ASSERT_NE(hash, std::string::npos) << rule.id;
    EXPECT_TRUE(anchors.count(rule.docs.substr(hash + 1)))
        << rule.id << " cites " << rule.docs << ", which docs/field-messages.md lacks";
    EXPECT_NE(rule.said_by.find("LinuxCNC"), std::string::npos) << rule.id << ": name LinuxCNC's source";
  }
}

TEST(DoctorBook, RefusesABadPatternAndAMissingDocsSection) {
  EXPECT_THROW(
      D::MessageBook::load_string("watch: x\nrules:\n  - {id: a, kind: known, pattern: '('}\n", "t.yaml"),
      D::BookError);
  EXPECT_THROW(
      D::MessageBook::load_string("watch: x\nrules:\n  - {id: a, kind: finding, severity: error, title: t, "
                                  "pattern: p, evidence: e, cause: c, said_by: s, docs: README.md, "
                                  "fix: [f]}\n",
                                  "t.yaml"),
      D::BookError);
  EXPECT_THROW(D::MessageBook::load_string(
                   "watch: x\nrules:\n  - {id: a, kind: known, pattern: p}\n---\nx: 1\n", "t.yaml"),
               D::BookError);
}

// ------------------------------------------------------------ captured from real halrun runs
TEST(DoctorCaptured, CleanRunHasNoErrorAndEveryHm2LineIsKnown) {
  const auto d = of_capture("clean");
  for (const auto& f : d.findings) EXPECT_NE(f.severity, D::Severity::Error) << f.id << ": " << f.evidence;
  EXPECT_TRUE(d.unrecognised.empty()) << d.unrecognised.front().first.text;
  EXPECT_GT(d.known, 50u);  // the driver's start-up lines and the pin table
  // The non-realtime note comes twice (halrun's start and its unload): one finding, count 2.
  const auto* posix = find(d, "posix-non-realtime");
  ASSERT_TRUE(posix);
  EXPECT_EQ(posix->count, 2u);
  EXPECT_EQ(posix->severity, D::Severity::Note);
}

TEST(DoctorCaptured, BusRisingAtPowerUpLeavesTheUnderVoltageFaultLatched) {
  // i20sim's bus at 20 V when hm2_eth started the port, then raised to 320 V: the pin stays TRUE.
  const auto d = of_capture("busv");
  ASSERT_TRUE(names(d, "pin-8i20-fault"));
  EXPECT_EQ(find(d, "pin-8i20-fault")->evidence, "hm2_7i96s.0.8i20.0.0.fault.bus-underv is TRUE");
  const auto all = ids(d);
  EXPECT_EQ(std::count(all.begin(), all.end(), "pin-8i20-fault"), 1);  // the -not twin is no finding
}

TEST(DoctorCaptured, RemoteFaultStaysSticky) {
  const auto d = of_capture("remote");  // `ch 0 fault overcurrent on` while running
  ASSERT_TRUE(names(d, "pin-8i20-fault"));
  EXPECT_EQ(find(d, "pin-8i20-fault")->evidence, "hm2_7i96s.0.8i20.0.0.fault.overcurrent is TRUE");
  EXPECT_TRUE(names(d, "pin-fault-count"));
}

TEST(DoctorCaptured, LostRepliesFromTheEightI20StopThePort) {
  const auto d = of_capture("chdrop");  // `ch 0 drop 0.5`: half the 8I20's replies lost
  EXPECT_TRUE(names(d, "local-link-error"));
  EXPECT_TRUE(names(d, "sserial-comms-error"));
  EXPECT_TRUE(names(d, "sserial-port-stopped"));
  const auto* stopped = find(d, "sserial-port-stopped");
  ASSERT_TRUE(stopped);
  EXPECT_EQ(stopped->evidence, "smart-serial port 0 of hm2_7i96s.0 was stopped");
  ASSERT_EQ(stopped->said.size(), 1u);
  EXPECT_GT(stopped->said[0].line, 0u);
  EXPECT_NE(stopped->said[0].text.find("***Smart Serial Port 0 will be stopped***"), std::string::npos);
  const auto* comms = find(d, "sserial-comms-error");
  EXPECT_NE(comms->evidence.find("fault-lim 200"), std::string::npos) << comms->evidence;
}

TEST(DoctorCaptured, CardThatStopsAnsweringTripsHm2EthsPacketErrors) {
  const auto d = of_capture("mute");  // `card reset 300`: the card silent for 300 ms
  EXPECT_TRUE(names(d, "read-error"));
  EXPECT_TRUE(names(d, "pin-packet-error-exceeded"));
  EXPECT_TRUE(names(d, "pin-packet-error-level"));
}

TEST(DoctorCaptured, ServoThreadTooFastForTheLink) {
  const auto d = of_capture("doit");  // a 250 us servo thread: replies cannot come back in time
  EXPECT_TRUE(names(d, "read-error"));
  EXPECT_TRUE(names(d, "pin-packet-error-exceeded"));
}

// ------------------------------------------------------------ LinuxCNC's wording, from its sources
TEST(DoctorText, DoItNotClearedOnALateServoThread) {
  const auto d = of_text(
      "Note: Using POSIX realtime\n"
      "Unexpected realtime delay on task 0 with period 1000000\n"
      "hm2/hm2_7i92.0: Smart Serial port 0: DoIt not cleared from previous servo thread. Servo thread rate "
      "probably too fast. This message will not be repeated, but the hm2_7i92.0.sserial.0.fault-count pin "
      "will indicate if this is happening frequently.\n");
  EXPECT_EQ(ids(d), (std::vector<std::string>{"realtime-delay", "doit-not-cleared"}));
  EXPECT_EQ(find(d, "doit-not-cleared")->said[0].line, 3u);
  EXPECT_EQ(d.known, 1u);
}

TEST(DoctorText, RemoteErrorsOfBothLinuxCncWordingsAndDmesgPrefixes) {
  // 2.9 says "remote error = (29)"; later sserial.c says "error = (29)"; dmesg adds a time.
  const auto d = of_text(
      "hm2/hm2_7i96s.0: Smart serial card hm2_7i96s.0.8i20.0.0 remote error = (29) Under Voltage\n"
      "[  812.331207] hm2/hm2_7i96s.0: Smart serial card hm2_7i96s.0.8i20.0.0 error = (29) Under Voltage\n"
      "hm2/hm2_7i96s.0: Smart serial card hm2_7i96s.0.8i20.0.0 remote error = (24) Watchdog Fault\n");
  ASSERT_TRUE(names(d, "remote-under-voltage"));
  const auto* uv = find(d, "remote-under-voltage");
  EXPECT_EQ(uv->count, 2u);  // the same evidence: grouped
  EXPECT_EQ(uv->said.size(), 2u);
  EXPECT_EQ(uv->last_line, 2u);
  EXPECT_TRUE(names(d, "remote-watchdog"));
}

TEST(DoctorText, RepeatedLinesAreOneFindingWithACount) {
  std::string log;
  for (int i = 0; i < 50; ++i)
    log += "hm2/hm2_7i92.0: error finishing read! iter=" + std::to_string(1000 + i) + "\n";
  const auto d = of_text(log);
  ASSERT_EQ(d.findings.size(), 1u);
  EXPECT_EQ(d.findings[0].count, 50u);
  EXPECT_EQ(d.findings[0].said.size(), D::kKeptLines);
  EXPECT_EQ(d.findings[0].last_line, 50u);
}

TEST(DoctorText, WatchdogAndNewerHm2EthWording) {
  const auto d = of_text(
      "hm2/hm2_7i92.0: Watchdog has bit! (set the .has-bit pin to False to resume)\n"
      "hm2_7i92.0: Recording soft error that tripped hard io_error. iter=1234\n"
      "hm2/hm2_7i92.0: Smart Serial Error: port 0 channel 1. You may see this error if the FPGA card "
      "\"read\" thread is not running. This error message will not repeat.\n"
      "hm2/hm2_7i92.0: Smart Serial Error: You may see this error if the FPGA card read function is not "
      "running. This error message will not repeat.\n");
  EXPECT_EQ(ids(d),
            (std::vector<std::string>{"watchdog-has-bit", "eth-soft-error", "sserial-read-not-running"}));
  EXPECT_EQ(find(d, "sserial-read-not-running")->count, 2u);
}

TEST(DoctorText, UnknownCardLinesAreNamedNotDropped) {
  const auto d = of_text(
      "hm2/hm2_7i92.0: something hostmot2 says that no rule knows\n"
      "hm2/hm2_7i92.0: something hostmot2 says that no rule knows\n"
      "task: main loop took 0.012 seconds\n");
  EXPECT_TRUE(d.findings.empty());
  ASSERT_EQ(d.unrecognised.size(), 1u);
  EXPECT_EQ(d.unrecognised[0].count, 2u);
  EXPECT_EQ(d.unrecognised[0].first.line, 1u);
  EXPECT_EQ(d.lines, 3u);
}

TEST(DoctorText, PinTableOfAStoppedPort) {
  const auto d = of_text(
      "    13  bit   IN          FALSE  hm2_7i92.0.sserial.port-0.run\n"
      "    13  u32   OUT    0x000000CF  hm2_7i92.0.sserial.port-0.fault-count\n"
      "    13  bit   OUT         FALSE  hm2_7i92.0.8i20.0.1.fault.bus-underv\n"
      "    13  bit   OUT          TRUE  hm2_7i92.0.8i20.0.1.fault.bus-underv-not\n"
      "    13  bit   OUT          TRUE  hm2_7i92.0.io_error\n");
  EXPECT_EQ(ids(d), (std::vector<std::string>{"pin-run-false", "pin-fault-count", "pin-io-error"}));
  // i20 hal's file nets run to the machine (a setp on it would be refused); another file sets it.
  EXPECT_NE(find(d, "pin-run-false")->fix[0].find("switch the machine on"), std::string::npos);
  EXPECT_EQ(find(d, "pin-run-false")->fix[1],
            "Where run is set rather than netted, set it true again (halcmd setp "
            "hm2_7i92.0.sserial.port-0.run 1) once the cause is gone.");
  EXPECT_EQ(d.known, 2u);
}

// A configured machine's pins are netted: halcmd's `show pin` then ends the line with the
// signal ("==> sig" for an output, "<== sig" for an input). What a user pastes from a running
// machine reads as the bare pins do, and a netted -not twin that is TRUE is no fault.
TEST(DoctorText, PinsOfAConfiguredMachineReadWithTheirSignals) {
  const auto d = of_text(
      "Component Pins:\n"
      "Owner   Type  Dir         Value  Name\n"
      "    20  u32   OUT    0x00000026  hm2_7i92.0.sserial.port-0.fault-count ==> i20-port-errors\n"
      "    20  bit   IN          FALSE  hm2_7i92.0.sserial.port-0.run <== i20-port-run\n"
      "    20  bit   OUT          TRUE  hm2_7i92.0.8i20.0.1.fault.bus-underv ==> j1-8i20-fault-bus-underv\n"
      "    20  bit   OUT          TRUE  hm2_7i92.0.8i20.0.1.fault.overcurrent-not ==> j1-ok\n"
      "    20  bit   OUT          FALSE  hm2_7i92.0.8i20.0.1.fault.overcurrent ==> "
      "j1-8i20-fault-overcurrent\n");
  ASSERT_TRUE(names(d, "pin-8i20-fault"));
  EXPECT_EQ(find(d, "pin-8i20-fault")->evidence, "hm2_7i92.0.8i20.0.1.fault.bus-underv is TRUE");
  EXPECT_EQ(find(d, "pin-8i20-fault")->count, 1u) << "the TRUE -not twin is not a fault";
  EXPECT_TRUE(names(d, "pin-fault-count"));
  EXPECT_TRUE(names(d, "pin-run-false"));
  EXPECT_TRUE(d.unrecognised.empty()) << d.unrecognised.size() << " pin lines not read";
}

// After a few lost replies the level falls back to 0; the total still tells of the link (the
// 8I20's watchdog may have stopped the machine before the level reached its limit).
TEST(DoctorText, LostRepliesSinceTheStartAreNamedAfterTheLevelFellBack) {
  const auto d = of_text(
      "Component Pins:\n"
      "Owner   Type  Dir         Value  Name\n"
      "    20  bit   OUT         FALSE  hm2_7i92.0.packet-error-exceeded ==> i20-link-failed\n"
      "    20  s32   OUT             0  hm2_7i92.0.packet-error-level\n"
      "    20  u32   I/O    0x00000007  hm2_7i92.0.packet-error-total\n");
  ASSERT_TRUE(names(d, "pin-packet-error-total"));
  EXPECT_EQ(find(d, "pin-packet-error-total")->evidence, "hm2_7i92.0.packet-error-total is 0x00000007");
  EXPECT_FALSE(names(d, "pin-packet-error-level"));
  EXPECT_FALSE(names(d, "pin-packet-error-exceeded"));
  EXPECT_FALSE(names(of_text("    20  u32   I/O    0x00000000  hm2_7i92.0.packet-error-total\n"),
                     "pin-packet-error-total"));
}
