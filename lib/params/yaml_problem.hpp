// SPDX-License-Identifier: GPL-2.0-or-later
// The reason yaml-cpp gave for rejecting a file, in words a user can act on. Shared by the
// loaders of parameter overlays, profiles and fault tables.
#pragma once

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/yaml.h>

#include <string>
#include <string_view>

namespace i20::params {

// "not valid YAML: REASON". yaml-cpp stops nesting at 2000 levels with the bare message
// "bad file"; a real file nests three or four deep, so say what it was.
inline std::string yaml_problem(const YAML::Exception& e) {
  if (const auto* deep = dynamic_cast<const YAML::DeepRecursion*>(&e))
    return "not valid YAML: nested " + std::to_string(deep->depth()) +
           " levels deep, more than the parser takes (a real file nests a few levels)";
  return "not valid YAML: " + e.msg;
}

// Parses `yaml` read from `source`. A syntax error goes to `fail("SOURCE:LINE", problem)`,
// which throws the loader's own error type.
template <class Fail>
YAML::Node load_yaml(std::string_view yaml, const std::string& source, Fail&& fail) {
  try {
    return YAML::Load(std::string(yaml));
  } catch (const YAML::Exception& e) {
    fail(source + ":" + std::to_string(e.mark.line + 1), yaml_problem(e));
    throw;  // only if `fail` did not throw
  }
}

}  // namespace i20::params
