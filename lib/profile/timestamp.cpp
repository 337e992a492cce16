// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/timestamp.hpp"

#include <ctime>

namespace i20::profile {
namespace {

std::string format(std::chrono::system_clock::time_point when, const char* pattern) {
  const std::time_t t = std::chrono::system_clock::to_time_t(when);
  std::tm tm{};
  gmtime_r(&t, &tm);  // the reentrant form: no shared static buffer
  char buf[64];
  const auto n = std::strftime(buf, sizeof buf, pattern, &tm);
  return std::string(buf, n);
}

}  // namespace

std::string iso8601_utc(std::chrono::system_clock::time_point when) {
  return format(when, "%Y-%m-%dT%H:%M:%SZ");
}

std::string compact_utc(std::chrono::system_clock::time_point when) {
  return format(when, "%Y%m%d-%H%M%S");
}

}  // namespace i20::profile
