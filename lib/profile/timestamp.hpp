// SPDX-License-Identifier: GPL-2.0-or-later
// UTC timestamps for backup names and provenance comments.
#pragma once

#include <chrono>
#include <string>

namespace i20::profile {

// "2024-05-01T12:34:56Z"
std::string iso8601_utc(std::chrono::system_clock::time_point when);
// "20240501-123456": sorts by time, safe in file names.
std::string compact_utc(std::chrono::system_clock::time_point when);

}  // namespace i20::profile
