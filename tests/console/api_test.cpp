// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 console`'s API against the simulator, through the real program over a real socket:
// the values are the ones `i20 get` reads, an applied edit lands in the simulator's EEPROM
// (read back by `i20 get` after the console ended), a refused value writes nothing, an apply
// that is not the current preview's (stale, edited, forged, the card changed) writes nothing,
// faults are explained in `i20 faults`'s words, and Ctrl-C ends the console as it ends every
// command (exit 130, the card settled).
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
  // `headers`: more header lines ("I20-Preview: ...\r\n").
  testing::Reply post(const std::string& path, const std::string& body,
                      const std::string& headers = "") const {
    return ask(port_, testing::post_request(port_, path, body,
                                            cat(cookie(), "Origin: http://127.0.0.1:", std::to_string(port_),
                                                "\r\n", headers)));
  }
  // An apply naming the preview `id`.
  testing::Reply apply(const std::string& body, const std::string& id) const {
    return post("/api/apply", body, cat("I20-Preview: ", id, "\r\n"));
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

// The id a preview was given ("preview_id":"..."), "" when none.
std::string preview_id(const testing::Reply& preview) {
  const std::regex field(R"re("preview_id":"([0-9a-f]+)")re");
  std::smatch m;
  return std::regex_search(preview.body, m, field) ? std::string(m[1]) : "";
}

// The member `key` of a compact JSON text: its value, an object or array with what it
// holds, up to its matching bracket ("absent" when there is none).
std::string member(const std::string& json, const std::string& key) {
  const auto start = json.find(cat("\"", key, "\":"));
  if (start == std::string::npos) return "absent";
  const auto value = start + key.size() + 3;
  int depth = 0;
  bool in_string = false, escaped = false;
  for (auto i = value; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      ++depth;
    } else if ((c == '}' || c == ']') && --depth == 0) {
      return json.substr(value, i + 1 - value);
    }
  }
  return "absent";
}

// The rest of the first line of `text` that follows `prefix` ("" when none).
std::string line_after(const std::string& text, const std::string& prefix) {
  const auto start = text.find(prefix);
  if (start == std::string::npos) return "";
  const auto from = start + prefix.size();
  return text.substr(from, text.find('\n', from) - from);
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
  const auto applied = console.apply("NVKQP=72\nKQP=73", preview_id(preview));
  ASSERT_EQ(applied.status, 200) << applied.body;
  EXPECT_NE(applied.body.find(R"("outcome":"done")"), std::string::npos) << applied.body;
  EXPECT_NE(applied.body.find(R"("cell":"NVKQP")"), std::string::npos);
  // Each cell's outcome in `i20 set`'s words, not the transaction's internal state name.
  EXPECT_NE(applied.body.find(R"("state":"written, read back equal")"), std::string::npos) << applied.body;
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
  const auto range = console.post("/api/preview", "NVBRAKEONV=9999V");  // outside its range
  EXPECT_EQ(range.status, 422) << range.body;
  EXPECT_NE(range.body.find("outside its valid range"), std::string::npos) << range.body;
  const auto rule = console.post("/api/preview", "NVBRAKEOFFV=380V");  // above NVBRAKEONV: the manual's rule
  EXPECT_EQ(rule.status, 422) << rule.body;
  EXPECT_NE(rule.body.find(R"("outcome":"refused")"), std::string::npos) << rule.body;
  EXPECT_EQ(preview_id(rule), "");  // a refused preview cannot be applied
  EXPECT_EQ(console.post("/api/apply", "NVBRAKEOFFV=380V").status, 409);
  const auto bad = console.post("/api/preview", "NOSUCHPARAM=1");
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

// The page applies only what it previewed: an apply must name the current preview and carry
// its very lines. Judged by the card: every refused apply leaves NVKQP as it was, in RAM and
// in the EEPROM; the one matching apply at the end writes its value, so the refusals are not
// an apply that never works.
TEST_F(ConsoleApi, AnApplyWritesOnlyWhatItsPreviewShowed) {
  ConsoleProcess console(eeprom());
  ASSERT_TRUE(console.up());
  const auto before = raw_of(console.get("/api/params").body, "NVKQP");
  ASSERT_NE(before, "absent");
  ASSERT_NE(before, "55");
  ASSERT_NE(before, "60");
  const auto refused = [&](const testing::Reply& reply, const std::string& what) {
    EXPECT_EQ(reply.status, 409) << what << ": " << reply.body;
    EXPECT_NE(reply.body.find("nothing was written"), std::string::npos) << what << ": " << reply.body;
    EXPECT_EQ(raw_of(console.get("/api/params").body, "NVKQP"), before) << what;
  };

  refused(console.post("/api/apply", "NVKQP=60"), "no preview at all");
  const auto preview = console.post("/api/preview", "NVKQP=55");
  ASSERT_EQ(preview.status, 200) << preview.body;
  const auto id = preview_id(preview);
  ASSERT_EQ(id.size(), 32u) << preview.body;
  refused(console.apply("NVKQP=60", id), "the box edited to 60 after previewing 55");
  refused(console.apply("NVKQP=55", id), "the previewed values, but that preview was used up");

  const auto older = preview_id(console.post("/api/preview", "NVKQP=55"));
  const auto newer = preview_id(console.post("/api/preview", "NVKQP=57"));
  ASSERT_FALSE(older.empty());
  ASSERT_NE(older, newer);
  refused(console.apply("NVKQP=55", older), "a preview a newer one replaced");
  refused(console.apply("NVKQP=57", std::string(32, '0')), "a forged id");
  refused(console.apply("NVKQP=57", newer), "the current preview, but a forged apply used it up");

  const auto before_reset = preview_id(console.post("/api/preview", "NVKQP=57"));
  ASSERT_EQ(console.post("/api/reset", "").status, 200);
  refused(console.apply("NVKQP=57", before_reset), "a preview made before a reset");

  const auto current = preview_id(console.post("/api/preview", "NVKQP=57"));
  const auto applied = console.apply("NVKQP=57", current);
  EXPECT_EQ(applied.status, 200) << applied.body;
  EXPECT_EQ(raw_of(console.get("/api/params").body, "NVKQP"), "57");
  EXPECT_EQ(console.stop(), 130);
  EXPECT_EQ(get_raw(eeprom(), "NVKQP"), "57");
}

// The fault page's text is `i20 faults`'s and `i20 clear-faults`'s own words: the same "now:"
// and "why:" sentences the commands print, and no JSON object rendered as text.
TEST_F(ConsoleApi, ExplainsFaultsInTheWordsOfIFaults) {
  const std::string world = "busv 30";  // below BUSUNDERV: the under-voltage fault, its cause present
  const auto cli = test::run("i20", {"--sim", "--sim-control", world, "faults"});
  const auto cli_clear = test::run("i20", {"--sim", "--sim-control", world, "clear-faults"});
  const auto now = line_after(cli.out, "  now: ");
  const auto why = line_after(cli_clear.out, "  why:   ");
  ASSERT_NE(now.find("cause still present: BUSV is 30.00 V"), std::string::npos) << cli.out;
  ASSERT_NE(why.find("the cause is still present"), std::string::npos) << cli_clear.out;
  ConsoleProcess console(eeprom(), world);
  ASSERT_TRUE(console.up());

  const auto faults = console.get("/api/faults");
  ASSERT_EQ(faults.status, 200);
  const auto words = member(faults.body, "explained");
  EXPECT_NE(words.find(R"x("heading":"BUSLOVFAULT (bit 8, bus-under-voltage, maskable)")x"),
            std::string::npos)
      << words;
  EXPECT_NE(words.find(cat(R"("now":")", now, R"(")")), std::string::npos) << now << "\n" << words;
  EXPECT_NE(words.find(line_after(cli.out, "Fault output (TB1 pins 5-6): ")), std::string::npos) << words;
  EXPECT_EQ(words.find(R"(\")"), std::string::npos) << "JSON rendered as text: " << words;
  EXPECT_EQ(words.find("\"state\""), std::string::npos) << words;

  const auto cleared = console.post("/api/clear-faults", "");
  ASSERT_EQ(cleared.status, 200) << cleared.body;
  const auto said = member(cleared.body, "explained");
  EXPECT_NE(said.find(R"(, 0 cleared, 1 remaining")"), std::string::npos) << said;
  EXPECT_NE(said.find(cat(R"("why":")", why, R"(")")), std::string::npos) << why << "\n" << said;
  EXPECT_NE(said.find(R"x("heading":"BUSLOVFAULT (bit 8)")x"), std::string::npos) << said;
  EXPECT_EQ(said.find(R"(\")"), std::string::npos) << "JSON rendered as text: " << said;
}

// Between preview and apply another program changed the card: the page's "card holds"
// column is no longer true, so the apply is refused and the card keeps the other program's
// value (the simulator counts no write).
TEST(ConsoleOnCards, AnApplyIsRefusedWhenTheCardChangedSinceItsPreview) {
  SimProcess card;
  ASSERT_EQ(card.control("set NVKQP 63"), "ok");
  ConsoleProcess console(std::vector<std::string>{"--port", card.port()});
  ASSERT_TRUE(console.up());
  const auto id = preview_id(console.post("/api/preview", "NVKQP=64"));
  ASSERT_FALSE(id.empty());
  ASSERT_EQ(card.control("set NVKQP 62"), "ok");  // behind the console's back
  const auto writes = card.writes_seen();
  const auto applied = console.apply("NVKQP=64", id);
  EXPECT_EQ(applied.status, 409) << applied.body;
  EXPECT_NE(applied.body.find("the card changed since the preview"), std::string::npos) << applied.body;
  EXPECT_EQ(card.control("get NVKQP"), "62");
  EXPECT_EQ(card.writes_seen(), writes);
  EXPECT_EQ(console.stop(), 130);
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
    const auto applied = console.apply("NVKQP=64", preview_id(console.post("/api/preview", "NVKQP=64")));
    ASSERT_EQ(applied.status, 200) << applied.body;
    EXPECT_NE(applied.body.find(R"("outcome":"done")"), std::string::npos) << applied.body;
    EXPECT_EQ(card.control("get NVKQP"), "64");
    const auto faults = console.get("/api/faults");
    EXPECT_NE(faults.body.find("NOENABLEFAULT"), std::string::npos) << faults.body;
    const auto cleared = console.post("/api/clear-faults", "");
    EXPECT_EQ(cleared.status, 200) << cleared.body;
    EXPECT_NE(cleared.body.find(R"("outcome":"done")"), std::string::npos) << cleared.body;
    EXPECT_NE(cleared.body.find(R"x("cleared":["NOENABLEFAULT (bit 1)"])x"), std::string::npos)
        << cleared.body;
    EXPECT_EQ(card.control("get FAULT"), "0");
    EXPECT_EQ(console.stop(), 130);
  }
}

}  // namespace
}  // namespace i20::console
