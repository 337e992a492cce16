// SPDX-License-Identifier: GPL-2.0-or-later
// One outcome model and one exit-code map for every program (README "Exit codes").
//
//   0   done and verified (or nothing to do, or a dry run)
//   1   the card was not reached, and nothing was sent that is not confirmed
//   2   bad input (arguments, files, values): nothing was sent
//   3   refused by a safety rule: nothing was written
//   4   the card's state is uncertain, or a failed change was rolled back: the report names
//       every cell that may differ
//   5   faults remain latched
//   6   the output (stdout, a file, a backup, a log) was not written in full
//   130 interrupted, after the card was left in a known state
#pragma once

#include "error/error.hpp"

namespace i20::ops {

enum class Outcome {
  Done,         // applied and verified
  NothingToDo,  // the card already held every value: nothing was written
  DryRun,       // planned only, on request
  Failed,    // failed before anything was written: the card was not reached, or a backup could not be written
  BadInput,  // nothing was sent
  Refused,   // nothing was written
  RolledBack,    // a change failed; what was written was restored and verified
  Uncertain,     // some cell may differ from both the old and the new value
  FaultsRemain,  // faults stay latched after clearing
  Interrupted,   // Ctrl-C; the card was left in a known state
  OutputLost,    // stdout, a file, a backup or a log was not written in full; no partial file left
};

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitRefused = 3;
inline constexpr int kExitUncertain = 4;
inline constexpr int kExitFaultsRemain = 5;
inline constexpr int kExitOutputLost = 6;
inline constexpr int kExitInterrupted = 130;

int exit_code(Outcome outcome);
int exit_code(ErrorKind kind);
Outcome outcome_of(ErrorKind kind);
// "done", "nothing-to-do", "dry-run", "failed", "bad-input", "refused", "rolled-back",
// "uncertain", "faults-remain", "interrupted", "output-lost".
const char* to_string(Outcome outcome);
// The label printed before an error message on stderr: "error", "refused", "card state",
// "interrupted", ...
const char* error_label(ErrorKind kind);

// `i20 profile diff` answers as diff(1) does: 0 every target holds every value, 1 some value
// differs, 2 trouble (bad input, a card not reached, a value that is not a fact on the card);
// 130 stopped.
enum class Comparison { Same, Differs, Trouble, Interrupted };
int exit_code(Comparison comparison);
// Of several comparisons (a diff over many targets), the one that decides the exit code.
Comparison most_serious(Comparison a, Comparison b);

// Of several outcomes (a fleet), the one that needs attention first: uncertain outranks
// interrupted, not reached, refused and bad input; 0 only if every run ended well.
Outcome most_serious(Outcome a, Outcome b);

}  // namespace i20::ops
