// SPDX-License-Identifier: GPL-2.0-or-later
// A reset loads every NV value into its working twin (manual: "NV values become the working
// values" at power-up and after a software reset). An EEPROM value written on a 120 V bench
// is harmless until then; on a 320 V bus the reset makes it live at once (a BRAKEONV below
// the supply leaves the brake resistor on). So before any reset is sent, `i20 reset` and
// `--reset` on set/apply/fleet read what it would make live and judge that with the rules
// of the write transaction (profile::validate, with the measured bus): a refusal sends
// nothing beyond the reads.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "ops/core/amp.hpp"
#include "ops/core/cell_access.hpp"
#include "ops/core/outcome.hpp"
#include "ops/core/pending.hpp"
#include "params/param_db.hpp"
#include "profile/finding.hpp"
#include "profile/profile.hpp"

namespace i20::ops {

struct ResetJudgement {
  std::vector<std::string> pending;  // NV cells whose value the reset makes live
  // NV cells whose working twin is not a fact on this firmware: a reset may make them live,
  // so they are judged as if pending.
  std::vector<std::string> unknown_live;
  RawValues nv;                            // the NV values judged (as read, or as planned)
  std::optional<double> measured_bus_v;    // BUSV now, when it is a fact
  std::vector<profile::Finding> findings;  // errors refuse the reset; warnings when forced

  bool refused() const { return profile::has_errors(findings); }
  // Every refusing value and why, "; "-separated: "NVBRAKEONV: ... [bus-measured-brake]; ...".
  std::string reason() const;
};

// Reads every NV cell with a working twin, the twins and BUSV (reads only: nothing else is
// sent), and judges what the card runs with after a reset: every NV value, pending or
// already live (a power-up makes an EEPROM live without any reset). `planned`: the writes a transaction
// makes before its reset, judged as already in the EEPROM. `force` turns the measured-bus
// refusals into warnings, as it does for writes. Throws i20::Error when the card cannot be
// read (nothing was sent but reads).
ResetJudgement judge_reset(const params::ParamDb& db, CellAccess& card, bool force,
                           const profile::Profile* planned = nullptr);

// Cells the caller read already, for the same decision (the write transaction's snapshot of
// the cells the rules compare, and BUSV): `values` holds the card's answers, the facts among
// `asked`; a name asked and absent is no fact on this firmware, and is not asked again.
struct ReadAlready {
  RawValues values;
  std::set<std::string> asked;
};
// The same judgement, reading only the cells `already` does not hold: each cell is read once
// per transaction. A cell the card fails to answer for still throws, as above; nothing is
// judged on a guess.
ResetJudgement judge_reset(const params::ParamDb& db, CellAccess& card, bool force,
                           const profile::Profile* planned, const ReadAlready& already);

// For the transaction's --reset: the judgement's findings that `findings` does not hold yet
// (the profile's own values are judged by the transaction already). A card that cannot be
// read for it adds an error: a reset nobody could judge is not sent.
// `already`: what the transaction read for its own rules, not read again.
void add_reset_findings(std::vector<profile::Finding>& findings, const params::ParamDb& db, CellAccess& card,
                        bool force, const profile::Profile& planned, const ReadAlready& already = {});

struct ResetRun {
  ResetJudgement judgement;
  bool done = false;  // the reset was sent and the card answered again
  // Refused when the judgement stopped it (only reads were sent).
  Outcome outcome() const { return done ? Outcome::Done : Outcome::Refused; }
};

// `i20 reset`: judges, then resets unless refused (refused: nothing but reads was sent).
// Throws i20::Error when the card cannot be read or does not come back.
ResetRun reset_amp(Amp& amp, bool force);

}  // namespace i20::ops
