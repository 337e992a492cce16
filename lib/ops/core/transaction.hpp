// SPDX-License-Identifier: GPL-2.0-or-later
// The one write transaction under every command that changes a card: `i20 set`, `wpd`,
// `profile apply`, the fleet, `faults mask`. A command builds a profile (a small one for
// `set A=1 B=2`, one cell for `wpd X V`) and the transaction:
//
//  1. reads the cells it writes and the ones the manual's rules compare them with, plus
//     the measured bus voltage;
//  2. validates every value: ranges, the manual's cross-parameter rules judged on what the
//     card will hold, the card's fixed limits (30 A, 385 V brake, baud index) that no
//     overlay can widen, thresholds at or below the measured bus (refused without force);
//  3. plans: cells that already hold their value are skipped (EEPROM wear), the rest are
//     ordered so that every intermediate state obeys the same rules, and every write is
//     put to the device layer's own rules before the first one is sent;
//  4. backs the old values up to a file (profile apply), writes one cell at a time (the
//     device layer confirms NV mode before each EEPROM data write and after it), reads
//     every cell back, and on any failure or Ctrl-C restores what it wrote and verifies that;
//  5. reports each cell's state as read from the card at the end.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ops/core/cancel.hpp"
#include "ops/core/cell_access.hpp"
#include "ops/core/outcome.hpp"
#include "params/param_db.hpp"
#include "profile/finding.hpp"
#include "profile/plan.hpp"
#include "profile/profile.hpp"

namespace i20::ops {

struct TransactionOptions {
  bool dry_run = false;  // read, validate and plan; write nothing (no backup either)
  // Allow guarded parameters (e.g. NVBAUDRATE) and thresholds at or below the measured bus.
  bool force = false;
  // Reset the card once the EEPROM writes are verified, or when a reset is pending anyway
  // (an earlier write never followed by one), so the values take effect now. Refused when
  // the profile writes working values a reset would overwrite.
  bool reset = false;
  // Where the backup of the old values goes (created if missing); none when empty.
  std::optional<std::filesystem::path> backup_dir;
  std::string backup_label;           // file name part: the profile name, the unit number
  profile::AmpOrigin backup_origin;   // the card: recorded in the backup, checked by an undo
  std::chrono::system_clock::time_point when = std::chrono::system_clock::now();
  Cancel cancel;  // polled before the first write and between writes
  // Told the plan once it is made and checked, before anything is written (a single-target
  // apply prints it then, and each write as it happens).
  std::function<void(const profile::Plan&)> on_plan;
};

enum class CellStatus {
  Intended,  // holds the new value
  Original,  // holds the value it had before (the backup's)
  Other,     // holds something else
  Unknown,   // could not be read
};
const char* to_string(CellStatus status);

// The state of one cell the transaction wrote (or tried to), as read back at the end.
struct CellState {
  std::string cell;
  std::int64_t original = 0;
  std::int64_t intended = 0;
  std::optional<std::int64_t> actual;  // nullopt when unknown
  std::string actual_text;             // engineering units, or "unknown"
  CellStatus status = CellStatus::Unknown;
  std::string error;  // why it is unknown (a torn EEPROM cell says so)
};

// One write the transaction (or its rollback) did or attempted.
struct WriteRecord {
  std::string cell;
  std::int64_t value = 0;
  std::string value_text;
  bool ok = false;
  bool skipped = false;  // rollback only: the cell still held its original value
  std::string error;
};

struct TransactionResult {
  Outcome outcome = Outcome::Failed;
  std::string card;                        // CellAccess::describe()
  std::string reason;                      // one line: why refused, or what failed; empty when done
  Advice reason_advice = Advice::None;     // what overrides the refusal in `reason`, for the app to name
  std::vector<profile::Finding> findings;  // validation against the card's current values
  profile::Plan plan;                      // what would change; empty if the card could not be read
  std::filesystem::path backup;            // the backup file, if one was written
  std::vector<WriteRecord> writes;         // forward writes, in order
  std::vector<WriteRecord> rollback;       // restoring writes, in order
  std::vector<CellState> cells;            // every cell written or attempted, after the transaction
  std::vector<std::string> events;         // what the card did meanwhile (resets), for the user
  // The working twins of the EEPROM cells the profile writes, as read with the card's
  // current values before the first write (where their addresses are facts): what tells a
  // reset that left no STATUS bit (a power cycle) from none, should the card go silent.
  RawValues working_before;
  bool interrupted = false;   // Ctrl-C stopped it (the outcome says how it ended)
  bool reset_needed = false;  // EEPROM values changed and take effect at the next reset
  bool reset_done = false;
  std::string reset_error;  // the reset (or the check after it) failed; values stay verified
};

// Never throws for card failures: they end in one of the outcomes above.
TransactionResult run_transaction(const profile::Profile& profile, const params::ParamDb& db,
                                  CellAccess& card, const TransactionOptions& options = {});

// Working names of the parameters the manual's cross-parameter rules compare.
const std::vector<std::string>& rule_parameters();

}  // namespace i20::ops
