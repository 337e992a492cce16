// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/error.hpp"

namespace i20::profile {
namespace {

std::string compose(const std::string& where, const std::string& key, const std::string& rule,
                    const std::string& reason) {
  std::string text;
  if (!where.empty()) text += where + ": ";
  if (!key.empty()) text += key + ": ";
  text += reason;
  if (!rule.empty()) text += " [" + rule + "]";
  return text;
}

}  // namespace

ProfileError::ProfileError(std::string where, std::string key, std::string rule, const std::string& reason)
    : Error(compose(where, key, rule, reason), ErrorKind::BadInput),
      where_(std::move(where)),
      key_(std::move(key)),
      rule_(std::move(rule)),
      reason_(reason) {}

}  // namespace i20::profile
