// SPDX-License-Identifier: GPL-2.0-or-later
// ops::Session, the one session every program runs through: where the card is (the command
// line, then the environment Mesa's WPD/RPD read), what every failure means (one Outcome,
// one exit code), and a card left settled at the end.
#include "ops/core/session.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include "eth/running_host.hpp"
#include "ops/core/errors.hpp"
#include "ops/core/read.hpp"
#include "ops/faults.hpp"

namespace i20::ops {
namespace {

// Sets (or, with nullopt, unsets) environment variables for one test and restores them.
class Environment {
 public:
  explicit Environment(const std::map<std::string, std::optional<std::string>>& values) {
    for (const auto& [name, value] : values) {
      const char* old = std::getenv(name.c_str());
      saved_[name] = old ? std::optional<std::string>(old) : std::nullopt;
      set(name, value);
    }
  }
  ~Environment() {
    for (const auto& [name, value] : saved_) set(name, value);
  }
  Environment(const Environment&) = delete;
  Environment& operator=(const Environment&) = delete;

 private:
  static void set(const std::string& name, const std::optional<std::string>& value) {
    if (value)
      setenv(name.c_str(), value->c_str(), 1);
    else
      unsetenv(name.c_str());
  }
  std::map<std::string, std::optional<std::string>> saved_;
};

const std::optional<std::string> kUnset;

SessionOptions with(LegacyEnvironment legacy) {
  SessionOptions o;
  o.legacy = legacy;
  o.no_user_params = true;
  return o;
}

ErrorKind kind_of_construction(const SessionOptions& options) {
  try {
    Session session(options);
  } catch (const Error& e) {
    return e.kind();
  }
  ADD_FAILURE() << "the session was built";
  return ErrorKind::Failure;
}

TEST(SessionEnvironment, WpdAndRpdWithoutAnyPortIsBadInputBeforeAnythingIsOpened) {
  Environment env({{"COMPORT", kUnset}, {"BAUDRATE", kUnset}, {"PROTOCOL", kUnset}});
  EXPECT_EQ(kind_of_construction(with(LegacyEnvironment::Required)), ErrorKind::BadInput);
  Session i20(with(LegacyEnvironment::IfNoTarget));  // i20 names its own target later
  EXPECT_FALSE(i20.endpoint_if_any().has_value());
  EXPECT_THROW(i20.endpoint(), UsageError);
}

TEST(SessionEnvironment, ComportAndBaudrateNameTheCardWhenTheCommandLineDoesNot) {
  Environment env({{"COMPORT", "COM2"}, {"BAUDRATE", "115200"}, {"PROTOCOL", "lbp"}});
  Session session(with(LegacyEnvironment::Required));
  EXPECT_EQ(session.endpoint().kind, Endpoint::Kind::Serial);
  EXPECT_EQ(session.endpoint().path, "/dev/ttyS1") << "COM2, as WPD names the second port";
  EXPECT_EQ(session.options().link.baud, 115200u);
}

TEST(SessionEnvironment, TheCommandLineOutranksComport) {
  Environment env({{"COMPORT", "/dev/ttyUSB7"}, {"BAUDRATE", "9600"}, {"PROTOCOL", kUnset}});
  auto options = with(LegacyEnvironment::Required);
  options.target.sim = true;
  Session session(options);
  EXPECT_EQ(session.endpoint().kind, Endpoint::Kind::Sim);
  EXPECT_EQ(session.options().link.baud, 115200u) << "BAUDRATE belongs to COMPORT's port only";
}

TEST(SessionEnvironment, AProtocolOtherThanLbpOrABaudRateThatIsNoNumberIsBadInput) {
  {
    Environment env({{"COMPORT", "/dev/ttyUSB0"}, {"PROTOCOL", "MODBUS"}, {"BAUDRATE", kUnset}});
    EXPECT_EQ(kind_of_construction(with(LegacyEnvironment::Required)), ErrorKind::BadInput);
  }
  // 9600 and 57600 are baud rates, but not the 8I20's: setup mode is 115200 only.
  for (const char* baud : {"fast", "115200 ", "-9600", "0", "99999999", "9600", "57600"}) {
    Environment env({{"COMPORT", "/dev/ttyUSB0"}, {"PROTOCOL", kUnset}, {"BAUDRATE", baud}});
    EXPECT_EQ(kind_of_construction(with(LegacyEnvironment::Required)), ErrorKind::BadInput) << baud;
  }
}

TEST(SessionEnvironment, TestsAndToolsThatIgnoreTheEnvironmentAreNotSteeredByIt) {
  Environment env({{"COMPORT", "/dev/ttyUSB0"}, {"PROTOCOL", "MODBUS"}, {"BAUDRATE", "fast"}});
  Session session(with(LegacyEnvironment::Ignore));
  EXPECT_FALSE(session.endpoint_if_any().has_value());
}

TEST(SessionTargets, ComportIsTheTargetOfACommandWithoutTargetsAndNeverASecondOne) {
  Environment env({{"COMPORT", "/dev/ttyUSB3"}, {"BAUDRATE", kUnset}, {"PROTOCOL", kUnset}});
  Session session(with(LegacyEnvironment::IfNoTarget));
  const auto from_env = session.targets({});
  ASSERT_EQ(from_env.size(), 1u);
  EXPECT_EQ(from_env.front().path, "/dev/ttyUSB3");
  const auto named = session.targets({"sim", "sim"});
  ASSERT_EQ(named.size(), 2u) << "--target names the cards; COMPORT does not add one";
  EXPECT_EQ(named.front().kind, Endpoint::Kind::Sim);

  auto both = with(LegacyEnvironment::IfNoTarget);
  both.target.port = "/dev/ttyUSB1";
  Session explicit_port(both);
  EXPECT_THROW(explicit_port.targets({"sim"}), UsageError) << "--port and --target at once";
}

Failure meaning_of(const std::function<void()>& thrower) {
  try {
    thrower();
  } catch (...) {
    return failure_of_current_exception();
  }
  ADD_FAILURE() << "nothing was thrown";
  return {};
}

TEST(FailureMeaning, EveryFailureHasOneOutcomeAndOneLabel) {
  struct Case {
    std::function<void()> thrower;
    Outcome outcome;
    const char* label;
  };
  const Case cases[] = {
      {[] { throw UsageError("bad"); }, Outcome::BadInput, "error"},
      {[] { throw SafetyError("no"); }, Outcome::Refused, "refused"},
      {[] { throw AmpStateError("NV access mode may be on"); }, Outcome::Uncertain, "card state"},
      {[] { throw Cancelled("Ctrl-C"); }, Outcome::Interrupted, "interrupted"},
      {[] { throw LinkError("no answer"); }, Outcome::Failed, "error"},
      {[] { throw Error("faults remain", ErrorKind::FaultsRemain); }, Outcome::FaultsRemain, "faults remain"},
      {[] { (void)YAML::Load("a: [1, 2"); }, Outcome::BadInput, "error"},
      {[] { throw std::runtime_error("vector::at"); }, Outcome::Uncertain, "internal error"},
  };
  for (const auto& c : cases) {
    const auto f = meaning_of(c.thrower);
    EXPECT_EQ(f.outcome, c.outcome) << f.line.message;
    EXPECT_EQ(f.line.label, c.label) << f.line.message;
    EXPECT_EQ(f.advice, Advice::None);
  }
  const auto defect = meaning_of([] { throw std::runtime_error("vector::at"); });
  EXPECT_NE(defect.line.message.find("state is not known"), std::string::npos)
      << "a defect claims nothing about the card: " << defect.line.message;
}

TEST(FailureMeaning, ARefusalCarriesWhatOverridesItForTheAppToName) {
  auto f = meaning_of(
      [] { throw SafetyError("refusing to write NVBAUDRATE, a guarded parameter", Advice::Force); });
  EXPECT_EQ(f.outcome, Outcome::Refused);
  EXPECT_EQ(f.advice, Advice::Force);
  EXPECT_EQ(f.line.message, "refusing to write NVBAUDRATE, a guarded parameter");
  f = meaning_of([] { throw SafetyError("its address is not confirmed", Advice::AllowUnverified); });
  EXPECT_EQ(f.advice, Advice::AllowUnverified);
}

TEST(FailureMeaning, ARefusalBesideARunningHostAsksTheAppForItsPassiveHint) {
  const auto f = meaning_of([] { throw eth::RunningHostError("another host runs the card", {}); });
  EXPECT_EQ(f.outcome, Outcome::Refused);
  EXPECT_EQ(f.advice, Advice::RunningHost);
  EXPECT_EQ(f.line.message, "another host runs the card") << "the library names no flag of an app";
}

TEST(OutcomeMap, OneExitCodePerOutcomeAndDiffAnswersAsDiff1) {
  EXPECT_EQ(exit_code(Outcome::Done), 0);
  EXPECT_EQ(exit_code(Outcome::DryRun), 0);
  EXPECT_EQ(exit_code(Outcome::Failed), 1);
  EXPECT_EQ(exit_code(Outcome::BadInput), 2);
  EXPECT_EQ(exit_code(Outcome::Refused), 3);
  EXPECT_EQ(exit_code(Outcome::RolledBack), 4);
  EXPECT_EQ(exit_code(Outcome::Uncertain), 4);
  EXPECT_EQ(exit_code(Outcome::FaultsRemain), 5);
  EXPECT_EQ(exit_code(Outcome::Interrupted), 130);
  EXPECT_EQ(exit_code(Comparison::Same), 0);
  EXPECT_EQ(exit_code(Comparison::Differs), 1);
  EXPECT_EQ(exit_code(Comparison::Trouble), 2);
  EXPECT_EQ(most_serious(Comparison::Differs, Comparison::Trouble), Comparison::Trouble);
  EXPECT_EQ(most_serious(Comparison::Same, Comparison::Differs), Comparison::Differs);
}

TEST(OutcomeMap, ClearingFaultsThatRemainIsItsOwnOutcome) {
  ClearResult r;
  r.fault_before = 0x0102;
  r.after.fault = 0x0002;
  EXPECT_EQ(r.outcome(), Outcome::FaultsRemain);
  r.after.fault = 0;
  EXPECT_EQ(r.outcome(), Outcome::Done);
}

TEST(SessionCard, OpensIdentifiesAndSettlesTheSimulatorAndReadsOnlyFacts) {
  auto options = with(LegacyEnvironment::Ignore);
  options.target.sim = true;
  Session session(options);
  EXPECT_FALSE(session.card_open());
  EXPECT_EQ(session.settle().outcome, Outcome::Done) << "no card yet: nothing to settle";
  auto& amp = session.amp();
  EXPECT_TRUE(session.card_open());
  EXPECT_NE(amp.describe().find("8I20"), std::string::npos) << amp.describe();
  const auto readings = read_values(amp, std::vector<std::string>{"BUSV", "NVMAXCURRENT"});
  EXPECT_EQ(reading_outcome(readings), Outcome::Done);
  const auto settled = session.settle();
  EXPECT_EQ(settled.outcome, Outcome::Done);
  EXPECT_FALSE(settled.note.has_value()) << "no mode was left on: " << settled.note->message;
}

TEST(SessionCard, AFailureIsReportedOnceWithItsOutcomeAndTheCardIsSettledAfterIt) {
  auto options = with(LegacyEnvironment::Ignore);
  options.target.sim = true;
  Session session(options);
  (void)session.amp();
  FailureReport report;
  try {
    throw SafetyError("NVMAXCURRENT 40 A is above the card's 30 A");
  } catch (...) {
    report = session.fail();
  }
  EXPECT_EQ(report.outcome, Outcome::Refused) << "the card settled cleanly: the refusal stands";
  ASSERT_EQ(report.lines.size(), 1u);
  EXPECT_EQ(report.lines.front().label, "refused");
}

// A session that stays open (the console) runs one operation after another: each gets the
// whole deadline from begin_operation(), however long the session has been open. Without it
// the card's deadline, counted from its opening, refuses every exchange once it has passed.
TEST(SessionCard, EachOperationGetsTheWholeDeadline) {
  auto options = with(LegacyEnvironment::Ignore);
  options.target.sim = true;
  options.retry.operation_deadline = std::chrono::milliseconds(300);
  Session session(options);
  auto& amp = session.amp();
  const auto opened = std::chrono::steady_clock::now();  // the card was opened before this
  std::this_thread::sleep_until(opened + options.retry.operation_deadline);  // the subject: time
  EXPECT_THROW(read_values(amp, std::vector<std::string>{"BUSV"}), link::OutOfTime);
  session.begin_operation();
  EXPECT_EQ(reading_outcome(read_values(amp, std::vector<std::string>{"BUSV"})), Outcome::Done);
}

}  // namespace
}  // namespace i20::ops
