// Applying a profile to a card: validate, read, back up, write in a safe order, verify,
// and on any failure restore what was written. The result says exactly which state the
// card is left in; it is plain data for the CLI to print (or turn into JSON).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "params/param_db.hpp"
#include "profile/card_access.hpp"
#include "profile/finding.hpp"
#include "profile/plan.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

struct ApplyOptions {
  bool dry_run = false;  // read, validate and plan; write nothing (no backup either)
  bool force = false;    // allow guarded parameters (e.g. NVBAUDRATE)
  // Reset the card once the EEPROM writes are verified, so they take effect now. Refused
  // when the profile writes working values a reset would overwrite.
  bool reset = false;
  std::filesystem::path backup_dir = ".";  // where the backup goes (created if missing)
  std::chrono::system_clock::time_point when = std::chrono::system_clock::now();  // backup time stamp
};

enum class Outcome {
  Refused,         // nothing written: validation errors, card unreadable or backup failed
  DryRun,          // nothing written, on request; the plan is in the result
  NothingToDo,     // the card already holds every value; nothing written
  Applied,         // every planned write done and verified by read-back
  RolledBack,      // a write or the verify failed; every cell written restored and verified
  RollbackFailed,  // ... and the restore failed: `cells` says what each cell holds
};

// "refused", "dry-run", "nothing-to-do", "applied-and-verified",
// "rolled-back-and-verified", "rollback-failed".
const char* to_string(Outcome outcome);

enum class CellStatus {
  Intended,  // holds the profile's value
  Original,  // holds the value it had before the apply (the backup's)
  Other,     // holds something else
  Unknown,   // could not be read
};
const char* to_string(CellStatus status);

// The state of one cell the apply wrote (or tried to), as read back at the end.
struct CellState {
  std::string cell;
  std::int64_t original = 0;
  std::int64_t intended = 0;
  std::optional<std::int64_t> actual;  // nullopt when unknown
  std::string actual_text;             // engineering units, or "unknown"
  CellStatus status = CellStatus::Unknown;
  std::string error;  // why it is unknown
};

// One write the apply (or its rollback) did or attempted.
struct WriteRecord {
  std::string cell;
  std::int64_t value = 0;
  std::string value_text;
  bool ok = false;
  bool skipped = false;  // rollback only: the cell still held its original value
  std::string error;
};

struct ApplyResult {
  Outcome outcome = Outcome::Refused;
  std::string card;                   // CardAccess::describe()
  std::string reason;                 // one line: why refused, or what failed; empty when applied
  std::vector<Finding> findings;      // validation against the card's current values
  Plan plan;                          // what would change; empty if the card could not be read
  std::filesystem::path backup;       // the backup file, if one was written
  std::vector<WriteRecord> writes;    // forward writes, in order
  std::vector<WriteRecord> rollback;  // restoring writes, in order
  std::vector<CellState> cells;       // every cell written or attempted, after the apply
  bool reset_needed = false;          // EEPROM values changed and take effect at the next reset
  bool reset_done = false;
  std::string reset_error;  // the reset (or the check after it) failed; values stay verified
};

// Never throws for card failures: they end in one of the outcomes above.
ApplyResult apply(const Profile& profile, const params::ParamDb& db, CardAccess& card,
                  const ApplyOptions& options = {});

}  // namespace i20::profile
