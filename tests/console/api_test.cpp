// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 console`'s API against the simulator, through the real program over a real socket:
// the values are the ones `i20 get` reads, an applied edit lands in the simulator's EEPROM
// (read back by `i20 get` after the console ended), a refused value writes nothing, and
// Ctrl-C ends the console as it ends every command (exit 130, the card settled).
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <regex>

#include "harness.hpp"
#include "raw_client.hpp"

namespace i20::console {
namespace {

using test::SimProcess;
using testing::ask;
using testing::cat;

// A console on a simulator whose EEPROM lives in a file, so its writes outlive it.
class ConsoleProcess {
 public:
  // `world`: simulator control lines (--sim-control), e.g. a bus above its threshold.
  explicit ConsoleProcess(const std::string& eeprom, const std::string& world = "temp 35")
      : ConsoleProcess(std::vector<std::string>{"--sim", "--sim-eeprom", eeprom, "--sim-control", world}) {}
  // On any target: `target` holds its global options (--port PTY, --eth IP:PORT ...).
  explicit ConsoleProcess(std::vector<std::string> target) {
    for (const char* word : {"console", "--listen-port", "0"}) target.emplace_back(word);
    child_ = test::start("i20", target);
    std::string out;
    const std::regex url(R"(http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]{32}))");
    std::smatch m;
    while (!std::regex_search(out, m, url)) {
      pollfd p{child_.out_fd, POLLIN, 0};
      if (::poll(&p, 1, 10000) <= 0) break;
      char buffer[512];
      const auto n = ::read(child_.out_fd, buffer, sizeof buffer);
      if (n <= 0) break;
      out.append(buffer, static_cast<std::size_t>(n));
    }
    if (m.empty()) return;
    port_ = static_cast<unsigned short>(std::stoi(m[1]));
    token_ = m[2];
  }
  ~ConsoleProcess() {
    if (child_.pid > 0) stop();
  }
  // Ctrl-C; the exit code.
  int stop() {
    ::kill(child_.pid, SIGINT);
    int status = 0;
    ::waitpid(child_.pid, &status, 0);
    child_.pid = -1;
    ::close(child_.out_fd);
    ::close(child_.err_fd);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  bool up() const { return port_ != 0; }
  testing::Reply get(const std::string& path) const {
    return ask(port_, testing::get_request(port_, path, cookie()));
  }
  testing::Reply post(const std::string& path, const std::string& body) const {
    return ask(port_, testing::post_request(
                          port_, path, body,
                          cat(cookie(), "Origin: http://127.0.0.1:", std::to_string(port_), "\r\n")));
  }

 private:
  std::string cookie() const { return cat("Cookie: i20_console=", token_, "\r\n"); }
  test::Child child_;
  unsigned short port_ = 0;
  std::string token_;
};

// The raw count the API gives for one parameter ("name":"X",...,"raw":N).
std::string raw_of(const std::string& json, const std::string& name) {
  const std::regex field(
      cat(R"(\{"name":")", name, R"(","space":"[a-z]+","unit":"[^"]*","raw":(-?\d+|null))"));
  std::smatch m;
  return std::regex_search(json, m, field) ? std::string(m[1]) : "absent";
}

// `i20 --sim --sim-eeprom FILE get --raw NAME`: "36000".
std::string get_raw(const std::string& eeprom, const std::string& name) {
  const auto r = test::run("i20", {"--sim", "--sim-eeprom", eeprom, "get", "--raw", name});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const auto eq = r.out.find(" = ");
  return eq == std::string::npos ? r.out : r.out.substr(eq + 3, r.out.find('\n') - eq - 3);
}

// JSON without the whitespace between tokens, so the CLI's indented output compares with
// the API's compact one.
std::string compact(const std::string& json) {
  std::string out;
  bool in_string = false, escaped = false;
  for (const char c : json) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == ' ' || c == '\n') {
      continue;
    }
    out += c;
  }
  return out;
}

// The "fault" member of an `i20 faults --json` document.
std::string fault_member(const std::string& json) {
  const auto start = json.find(R"("fault":{)");
  const auto end = json.find(R"(,"status":{)", start);
  return start == std::string::npos || end == std::string::npos ? "absent" : json.substr(start, end - start);
}

class ConsoleApi : public ::testing::Test {
 protected:
  std::string eeprom() const { return (dir_ / "card.eeprom").string(); }
  test::TempDir dir_;
};

TEST_F(ConsoleApi, ShowsTheValuesIGetReads) {
  // A value that is not the simulator's default, so a console reading defaults would fail.
  ASSERT_EQ(test::run("i20", {"--sim", "--sim-eeprom", eeprom(), "set", "NVKQP=61"}).exit_code, 0);
  const std::vector<std::string> names{"NVKQP", "NVBRAKEONV", "NVMAXCURRENT", "NVBUSOVERV", "BRAKEONV"};
  std::vector<std::string> expected;
  for (const auto& n : names) expected.push_back(get_raw(eeprom(), n));
  ConsoleProcess console(eeprom());
  ASSERT_TRUE(console.up());
  const auto params = console.get("/api/params");
  ASSERT_EQ(params.status, 200) << params.body;
  for (std::size_t i = 0; i < names.size(); ++i)
    EXPECT_EQ(raw_of(params.body, names[i]), expected[i]) << names[i];
  EXPECT_EQ(expected[0], "61");
}

TEST_F(ConsoleApi, AnAppliedEditLandsInTheCard) {
  ConsoleProcess console(eeprom());
  ASSERT_TRUE(console.up());
  const auto preview = console.post("/api/preview", "NVKQP=72\nKQP=73");
  ASSERT_EQ(preview.status, 200) << preview.body;
  EXPECT_NE(preview.body.find(R"("outcome":"dry-run")"), std::string::npos) << preview.body;
  EXPECT_NE(raw_of(console.get("/api/params").body, "NVKQP"), "72");  // a preview writes nothing
  const auto applied = console.post("/api/apply", "NVKQP=72\nKQP=73");
  ASSERT_EQ(applied.status, 200) << applied.body;
  EXPECT_NE(applied.body.find(R"("outcome":"done")"), std::string::npos) << applied.body;
  EXPECT_NE(applied.body.find(R"("cell":"NVKQP")"), std::string::npos);
  EXPECT_EQ(raw_of(console.get("/api/params").body, "KQP"), "73");  // the working value, in RAM
  const auto reset = console.post("/api/reset", "");                // makes the EEPROM's 72 live
  ASSERT_EQ(reset.status, 200) << reset.body;
  EXPECT_NE(reset.body.find(R"("made_live":["NVKQP"])"), std::string::npos) << reset.body;
  EXPECT_EQ(raw_of(console.get("/api/params").body, "KQP"), "72");
  EXPECT_EQ(console.stop(), 130);               // Ctrl-C, the card settled
  EXPECT_EQ(get_raw(eeprom(), "NVKQP"), "72");  // in the EEPROM
}

TEST_F(ConsoleApi, ARefusedValueWritesNothing) {
  const auto before = get_raw(eeprom(), "NVBRAKEONV");
  const auto off_before = get_raw(eeprom(), "NVBRAKEOFFV");
  ConsoleProcess console(eeprom());
  ASSERT_TRUE(console.up());
  const auto range = console.post("/api/apply", "NVBRAKEONV=9999V");  // outside its range
  EXPECT_EQ(range.status, 422) << range.body;
  EXPECT_NE(range.body.find("outside its valid range"), std::string::npos) << range.body;
  const auto rule = console.post("/api/apply", "NVBRAKEOFFV=380V");  // above NVBRAKEONV: the manual's rule
  EXPECT_EQ(rule.status, 422) << rule.body;
  EXPECT_NE(rule.body.find(R"("outcome":"refused")"), std::string::npos) << rule.body;
  const auto bad = console.post("/api/apply", "NOSUCHPARAM=1");
  EXPECT_EQ(bad.status, 400) << bad.body;
  EXPECT_EQ(console.stop(), 130);
  EXPECT_EQ(get_raw(eeprom(), "NVBRAKEONV"), before);
  EXPECT_EQ(get_raw(eeprom(), "NVBRAKEOFFV"), off_before);
}

TEST_F(ConsoleApi, OverviewAndFaultsExplainTheCard) {
  ConsoleProcess console(eeprom());
  ASSERT_TRUE(console.up());
  const auto overview = console.get("/api/overview");
  ASSERT_EQ(overview.status, 200);
  EXPECT_NE(overview.body.find(R"("swrevision":"0xE120")"), std::string::npos) << overview.body;
  EXPECT_NE(overview.body.find(R"("working_map_confirmed":true)"), std::string::npos);
  EXPECT_NE(overview.body.find(R"("busv_v":320)"), std::string::npos);
  const auto faults = console.get("/api/faults");
  ASSERT_EQ(faults.status, 200);
  EXPECT_NE(faults.body.find(R"("register":"FAULT")"), std::string::npos);
  const auto cleared = console.post("/api/clear-faults", "");
  EXPECT_EQ(cleared.status, 200) << cleared.body;
  EXPECT_NE(cleared.body.find(R"("outcome":"done")"), std::string::npos) << cleared.body;
  EXPECT_EQ(console.get("/api/nothing").status, 404);
}

TEST_F(ConsoleApi, ExplainsFaultsAsIFaultsDoes) {
  const std::string world = "busv 410";  // above BUSOVERV: the card latches its over-voltage faults
  const auto cli = test::run("i20", {"--sim", "--sim-control", world, "faults", "--json"});
  ConsoleProcess console(eeprom(), world);
  ASSERT_TRUE(console.up());
  const auto api = console.get("/api/faults");
  ASSERT_EQ(api.status, 200);
  const auto expected = fault_member(compact(cli.out));
  EXPECT_NE(expected.find("BUSHIVFAULT"), std::string::npos) << cli.out;
  EXPECT_EQ(fault_member(api.body), expected);
  // The cause is still there, so clearing leaves the fault latched: said, with its status.
  const auto cleared = console.post("/api/clear-faults", "");
  EXPECT_EQ(cleared.status, 200);
  EXPECT_NE(cleared.body.find(R"("outcome":"faults-remain")"), std::string::npos) << cleared.body;
}

// The same console on a card behind a serial line (i20sim on a pty) and behind a virtual
// 7I96S/7I92T (i20sim --eth, SSLBP passthrough): it reads what the card holds, writes what
// it is asked to (the simulator's own value proves the write reached the card), and clears
// a fault whose cause is gone.
TEST(ConsoleOnCards, ReadsChangesAndClearsFaultsOnAPtyCardAndAVirtualEthernetCard) {
  for (const auto transport : {SimProcess::Transport::Pty, SimProcess::Transport::Eth}) {
    const bool eth = transport == SimProcess::Transport::Eth;
    SCOPED_TRACE(eth ? "virtual Ethernet card" : "pty card");
    SimProcess card({"--enable", "off"}, transport);  // NOENABLEFAULT latched
    ASSERT_EQ(card.control("enable on"), "ok");       // its cause gone, the fault stays latched
    ASSERT_EQ(card.control("set NVKQP 63"), "ok");
    const auto target = eth ? std::vector<std::string>{"--eth", card.port(), "--channel", "0"}
                            : std::vector<std::string>{"--port", card.port()};
    ConsoleProcess console(target);
    ASSERT_TRUE(console.up());
    EXPECT_EQ(raw_of(console.get("/api/params").body, "NVKQP"), "63");
    const auto applied = console.post("/api/apply", "NVKQP=64");
    ASSERT_EQ(applied.status, 200) << applied.body;
    EXPECT_NE(applied.body.find(R"("outcome":"done")"), std::string::npos) << applied.body;
    EXPECT_EQ(card.control("get NVKQP"), "64");
    const auto faults = console.get("/api/faults");
    EXPECT_NE(faults.body.find("NOENABLEFAULT"), std::string::npos) << faults.body;
    const auto cleared = console.post("/api/clear-faults", "");
    EXPECT_EQ(cleared.status, 200) << cleared.body;
    EXPECT_NE(cleared.body.find(R"("outcome":"done")"), std::string::npos) << cleared.body;
    EXPECT_EQ(card.control("get FAULT"), "0");
    EXPECT_EQ(console.stop(), 130);
  }
}

}  // namespace
}  // namespace i20::console
