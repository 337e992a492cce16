// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/outcome.hpp"

namespace i20::ops {

int exit_code(Outcome outcome) {
  switch (outcome) {
    case Outcome::Done:
    case Outcome::NothingToDo:
    case Outcome::DryRun: return kExitOk;
    case Outcome::Failed: return kExitFailed;
    case Outcome::BadInput: return kExitBadInput;
    case Outcome::Refused: return kExitRefused;
    case Outcome::RolledBack:
    case Outcome::Uncertain: return kExitUncertain;
    case Outcome::FaultsRemain: return kExitFaultsRemain;
    case Outcome::Interrupted: return kExitInterrupted;
    case Outcome::OutputLost: return kExitOutputLost;
  }
  return kExitUncertain;
}

Outcome outcome_of(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::Failure: return Outcome::Failed;
    case ErrorKind::BadInput: return Outcome::BadInput;
    case ErrorKind::Refused: return Outcome::Refused;
    case ErrorKind::Uncertain: return Outcome::Uncertain;
    case ErrorKind::FaultsRemain: return Outcome::FaultsRemain;
    case ErrorKind::Cancelled: return Outcome::Interrupted;
    case ErrorKind::OutputLost: return Outcome::OutputLost;
  }
  return Outcome::Uncertain;
}

int exit_code(ErrorKind kind) {
  return exit_code(outcome_of(kind));
}

const char* to_string(Outcome outcome) {
  switch (outcome) {
    case Outcome::Done: return "done";
    case Outcome::NothingToDo: return "nothing-to-do";
    case Outcome::DryRun: return "dry-run";
    case Outcome::Failed: return "failed";
    case Outcome::BadInput: return "bad-input";
    case Outcome::Refused: return "refused";
    case Outcome::RolledBack: return "rolled-back";
    case Outcome::Uncertain: return "uncertain";
    case Outcome::FaultsRemain: return "faults-remain";
    case Outcome::Interrupted: return "interrupted";
    case Outcome::OutputLost: return "output-lost";
  }
  return "?";
}

const char* error_label(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::Failure:
    case ErrorKind::BadInput:
    case ErrorKind::OutputLost: return "error";
    case ErrorKind::Refused: return "refused";
    case ErrorKind::Uncertain: return "card state";
    case ErrorKind::FaultsRemain: return "faults remain";
    case ErrorKind::Cancelled: return "interrupted";
  }
  return "error";
}

int exit_code(Comparison comparison) {
  switch (comparison) {
    case Comparison::Same: return kExitOk;
    case Comparison::Differs: return 1;
    case Comparison::Trouble: return 2;
    case Comparison::Interrupted: return kExitInterrupted;
  }
  return 2;
}

Comparison most_serious(Comparison a, Comparison b) {
  return static_cast<int>(b) > static_cast<int>(a) ? b : a;
}

namespace {

// Lower is more serious.
int rank(Outcome o) {
  switch (o) {
    case Outcome::Uncertain: return 0;
    case Outcome::RolledBack: return 1;
    case Outcome::Interrupted: return 2;
    case Outcome::FaultsRemain: return 3;
    case Outcome::Failed: return 4;
    case Outcome::OutputLost: return 5;
    case Outcome::Refused: return 6;
    case Outcome::BadInput: return 7;
    case Outcome::Done: return 8;
    case Outcome::DryRun: return 9;
    case Outcome::NothingToDo: return 10;
  }
  return 0;
}

}  // namespace

Outcome most_serious(Outcome a, Outcome b) {
  return rank(b) < rank(a) ? b : a;
}

}  // namespace i20::ops
