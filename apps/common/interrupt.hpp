// SPDX-License-Identifier: GPL-2.0-or-later
// Ctrl-C handling: SIGINT/SIGTERM set a flag that the device layer polls between
// exchanges, so NV mode and RPC memory access are always left before the process ends.
// A second Ctrl-C while cleanup runs restores the default action.
#pragma once

#include <atomic>

namespace i20::app {

// Installs the handlers (idempotent) and returns the flag they set.
const std::atomic<bool>& install_interrupt_handler();
bool interrupted();

}  // namespace i20::app
