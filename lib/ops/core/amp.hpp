// SPDX-License-Identifier: GPL-2.0-or-later
// One 8I20, open and identified: the one policy every command starts from.
//
// Opening a card (1) opens and locks the link, (2) reads its identity and the two modes a
// dead session may have left on (NV access, RPC memory) and switches them off, (3) resolves
// the parameter database for the firmware it reports (overlays for that SWREVISION), and
// (4) decodes its pre-loaded RPC table, read-only, which names the FAULT, STATUS, BUSV,
// TEMPERATURE, ANGLE and QSETPOINT addresses on any firmware. Only then is a command built:
// every address a command uses comes from that resolved map, which is a value the card owns.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "device/amp.hpp"
#include "link/link.hpp"
#include "link/wait_bound.hpp"
#include "ops/core/cancel.hpp"
#include "ops/core/endpoint.hpp"
#include "ops/core/retry.hpp"
#include "params/param_db.hpp"

namespace i20::ops {

struct Identity {
  device::AmpInfo info;                    // as read when the card was opened
  std::vector<std::string> modes_left;     // modes found on and switched off ("NV access mode")
  std::string rpc_note;                    // which RPC named addresses, or why none did
  std::vector<std::string> rpc_confirmed;  // parameters the RPC table confirmed
};

struct OpenOptions {
  LinkSettings link;
  RetryPolicy retry;
};

class Amp {
 public:
  // Opens the endpoint and identifies the card. Throws i20::Error (link errors when the
  // card does not answer; UsageError for a target that is not an 8I20).
  static std::unique_ptr<Amp> open(const Endpoint& endpoint, const params::ParamDb& loaded,
                                   const OpenOptions& options, Cancel cancel = {});
  // The same over a link the caller opened (tests, the simulator with injected faults, a
  // fleet's shared Ethernet port): the deadline counts from `opened_at`, when the caller
  // began opening that link.
  static std::unique_ptr<Amp> attach(
      std::unique_ptr<link::Link> link, Endpoint endpoint, const params::ParamDb& loaded,
      RetryPolicy retry = {}, Cancel cancel = {},
      std::chrono::steady_clock::time_point opened_at = std::chrono::steady_clock::now());

  const Identity& identity() const { return identity_; }
  // The database resolved for this card: every address a command uses comes from here.
  const params::ParamDb& db() const { return *db_; }
  device::Amp8i20& device() { return *amp_; }
  link::Link& link() { return *link_; }
  const Endpoint& endpoint() const { return endpoint_; }
  const Cancel& cancel() const { return cancel_; }
  const RetryPolicy& retry() const { return retry_; }
  std::uint16_t swrevision() const { return *identity_.info.swrevision; }

  // "8I20 unit 0x00012345, SWREVISION 0xE120, on /dev/ttyUSB0".
  std::string describe() const;
  // Why a value at this parameter's address is not a fact on this card, or "" when it is:
  // "address not confirmed for SWREVISION 0x1234".
  std::string unconfirmed_reason(const params::Param& param) const;

  // While one of these lives, Ctrl-C does not stop the card's exchanges: the write
  // transaction holds one and decides itself when a stop is safe (never inside an EEPROM
  // sequence or a restore).
  class Uninterruptible {
   public:
    explicit Uninterruptible(Amp& amp);
    ~Uninterruptible();
    Uninterruptible(const Uninterruptible&) = delete;
    Uninterruptible& operator=(const Uninterruptible&) = delete;

   private:
    Amp& amp_;
  };

  // While one of these lives, the card is on its way back (restoring what a failed change
  // wrote, leaving NV access or RPC memory mode): its exchanges run to the settle bound, past
  // the operation's deadline (bound(), below).
  class Settling {
   public:
    explicit Settling(Amp& amp);
    ~Settling();
    Settling(const Settling&) = delete;
    Settling& operator=(const Settling&) = delete;

   private:
    Amp& amp_;
    bool was_settling_;
  };

  // Runs `step` again on a link error, `retry().attempts` times in all: the one loop over
  // a lost exchange, since the links under an ops::Amp send each exchange once (retry.hpp). A
  // card still silent after that is asked again within the silence window (retry.hpp).
  // `step` must be harmless to run twice: reads, or the writes that switch a mode off.
  // Every wait in `step` ends by bound(); past it nothing is sent (link::OutOfTime).
  // Past the operation's deadline (retry.hpp) an exchange is sent once, unless it is the
  // way back (settling).
  template <class F>
  auto with_retries(F&& step) {
    for (unsigned attempt = 1;; ++attempt) {
      if (!uninterruptible_) cancel_.check("reading");
      const link::WaitBound bounded(bound());
      require_time_left();
      try {
        auto result = step();
        answered();
        return result;
      } catch (const link::OutOfTime&) {
        throw;  // nothing was sent, and nothing more may be
      } catch (const link::LinkError& e) {
        unanswered(e);
        if ((attempt >= retry_.attempts || past_deadline()) && !wait_for_answer(e)) throw;
        ++retries_;
      }
    }
  }
  // True once the operation has run longer than RetryPolicy::operation_deadline, counted
  // from the start of the card's opening; the way back (Settling) is never past it.
  bool past_deadline() const { return !settling_ && std::chrono::steady_clock::now() >= deadline_; }
  // The end of every wait now: the operation's deadline, or on the way back the settle
  // bound after it (timing::kSettleBudget), or for leaving a mode its own budget from the
  // moment it starts (timing::kLeaveModeBudget), whichever is later.
  std::chrono::steady_clock::time_point bound() const;
  // Throws link::OutOfTime (nothing sent) once bound() has passed.
  void require_time_left() const;
  // A new operation on the same card (a watch's next sample): its deadline counts from now.
  void restart_deadline() {
    deadline_ = std::chrono::steady_clock::now() + retry_.operation_deadline;
    leave_mode_bound_.reset();
  }
  std::size_t retries() const { return retries_; }
  // Times a silent card was asked again within the silence window.
  std::size_t probes() const { return probes_; }
  // How often the card failed an exchange and answered a later one: the card may have
  // reset in between (a power cycle leaves no new STATUS bit).
  std::size_t silences_ended() const { return silences_ended_; }
  // The silence bookkeeping of with_retries() and settle(), for exchanges outside them too
  // (a write, which is never repeated as it is).
  void answered();
  void unanswered(const link::LinkError& e);

  // When the line died while the card was in NV access or RPC memory mode and leaving it
  // failed, asks the card again to leave (per the retry policy, Ctrl-C or not). Returns the
  // mode it left, "" when there was none; throws AmpStateError (exit 4) naming the mode
  // and the way back when the card still does not confirm. Every use case ends with it.
  std::string settle();
  // The last settle() threw: its warning has been given (in a run's report or an error
  // line), so a later one that fails the same way need not say it again.
  bool unsettled_said() const { return unsettled_said_; }
  void count_retry() { ++retries_; }

 private:
  Amp(std::unique_ptr<link::Link> link, Endpoint endpoint, RetryPolicy retry, Cancel cancel,
      std::chrono::steady_clock::time_point opened_at);
  void identify(const params::ParamDb& loaded);
  // Sleeps until the next probe when the error is one a card recovers from and the silence
  // window is still open; false (at once) otherwise. A stop request ends the wait unless
  // the card is uninterruptible.
  bool wait_for_answer(const link::LinkError& e);
  std::vector<params::ParamDb::Evidence> read_rpc_evidence(const params::ParamDb& resolved);

  std::unique_ptr<link::Link> link_;
  Endpoint endpoint_;
  RetryPolicy retry_;
  Cancel cancel_;
  Identity identity_;
  std::unique_ptr<params::ParamDb> db_;
  std::unique_ptr<device::Amp8i20> amp_;
  std::size_t retries_ = 0;
  std::size_t probes_ = 0;
  std::size_t silences_ended_ = 0;
  // When the card's first unanswered exchange of the current silence failed.
  std::optional<std::chrono::steady_clock::time_point> silent_since_;
  std::chrono::steady_clock::time_point deadline_;  // the operation's (retry.hpp)
  // From the operation's first settle(): the end of leaving a mode's own budget.
  std::optional<std::chrono::steady_clock::time_point> leave_mode_bound_;
  bool unsettled_said_ = false;
  bool uninterruptible_ = false;
  bool settling_ = false;
};

}  // namespace i20::ops
