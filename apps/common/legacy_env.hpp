// The environment Mesa's WPD/RPD read (manual, "SETUP COMMUNICATION WITH 8I20"):
// COMPORT (COM1 or, here, a device path), BAUDRATE (115200), PROTOCOL (must be LBP).
#pragma once

#include "session.hpp"

namespace i20::app {

// Fills port and baud from COMPORT/BAUDRATE unless a target was given on the command
// line, and rejects a PROTOCOL other than LBP. Throws UsageError with the fix.
void apply_legacy_environment(GlobalOptions& options);

}  // namespace i20::app
