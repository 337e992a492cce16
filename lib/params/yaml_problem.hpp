// SPDX-License-Identifier: GPL-2.0-or-later
// The reason yaml-cpp gave for rejecting a file, in words a user can act on. Shared by the
// loaders of parameter overlays, profiles and fault tables.
#pragma once

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/yaml.h>

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

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
// A file holds one document: a second one after `---` (even a broken one) is refused, not
// silently dropped, so nothing a user wrote goes unread.
template <class Fail>
YAML::Node load_yaml(std::string_view yaml, const std::string& source, Fail&& fail) {
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(std::string(yaml));
  } catch (const YAML::Exception& e) {
    fail(source + ":" + std::to_string(e.mark.line + 1), yaml_problem(e));
    throw;  // only if `fail` did not throw
  }
  // An empty document (a stray `---` at the end) drops nothing; any other is refused.
  for (std::size_t i = 1; i < documents.size(); ++i) {
    if (documents[i].IsNull()) continue;
    const int line = documents[i].Mark().line;
    fail(
        source + ":" + std::to_string(line >= 0 ? line + 1 : 1),
        "a second YAML document (after ---): a file holds one; split it into files, or remove the extra one");
    throw std::logic_error("load_yaml: fail() returned");
  }
  return documents.empty() ? YAML::Node() : documents.front();
}

}  // namespace i20::params
