// SPDX-License-Identifier: GPL-2.0-or-later
// Fault-injection switches: ways the card, the cable or the USB adapter misbehave, so
// tests prove the client copes. All random choices come from `seed`, so a failing test
// replays exactly. Every switch can change while the simulator runs.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>

namespace i20::sim {

enum class EepromPowerLoss {
  None,
  Lost,  // power fails as the cell write starts: nothing lands
  Torn,  // power fails mid-write: only the first byte lands
};

struct Injection {
  double corrupt_rate = 0.0;  // probability that a reply byte is corrupted (one bit flipped)
  double drop_rate = 0.0;     // probability that a whole reply is lost (the command still executed)
  std::chrono::steady_clock::duration reply_delay{};  // extra latency before each reply
  // Reset the card (as a DSP watchdog reset: STATUS bit 4) right after the Nth command from now.
  std::optional<std::uint64_t> reset_after_commands{};
  bool clearfault_stuck = false;  // CLEARFAULT stays 1 and nothing is cleared
  // Power fails during the next EEPROM write; the card stays dead until power_cycle().
  EepromPowerLoss eeprom_power_loss = EepromPowerLoss::None;
  // Execute N more commands, then ignore everything (no execution, no reply) until cleared.
  std::optional<std::uint64_t> answer_limit{};
  std::uint64_t seed = 1;
};

}  // namespace i20::sim
