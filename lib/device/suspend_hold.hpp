// SPDX-License-Identifier: GPL-2.0-or-later
// Ctrl-Z (SIGTSTP) while the card is in NV access or RPC memory mode would leave it there for
// as long as the process stays stopped: minutes, or for good if the terminal is then closed.
// So, as an editor restores the terminal before it stops, the tool settles the card first:
// while any SuspendHold lives (ModeGuard holds one for each mode it guards), a SIGTSTP is
// remembered instead of obeyed, and the process stops as soon as the last hold ends, with the
// card back in RAM access. Outside a hold Ctrl-Z stops the process at once, as usual.
#pragma once

namespace i20::device {

// Installs the SIGTSTP handler (idempotent; ops::install_stop_signals calls it). Without it
// Ctrl-Z keeps its default action.
void install_suspend_handler();

class SuspendHold {
 public:
  SuspendHold();
  ~SuspendHold();  // the last hold to end stops the process if a Ctrl-Z came meanwhile
  SuspendHold(const SuspendHold&) = delete;
  SuspendHold& operator=(const SuspendHold&) = delete;
};

}  // namespace i20::device
