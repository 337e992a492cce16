// SPDX-License-Identifier: GPL-2.0-or-later
// The environment Mesa's WPD/RPD read (manual, "SETUP COMMUNICATION WITH 8I20"):
// COMPORT (COM1 or, here, a device path or eth:// URL), BAUDRATE (115200), PROTOCOL (LBP).
#pragma once

#include "session.hpp"

namespace i20::app {

// Fills the port and baud from COMPORT/BAUDRATE unless a target was given on the command
// line, and rejects a PROTOCOL other than LBP. Throws UsageError with the fix. With
// `require_port` (wpd, rpd) a missing COMPORT is an error; i20 names its own.
void apply_legacy_environment(GlobalOptions& options, bool require_port);

}  // namespace i20::app
