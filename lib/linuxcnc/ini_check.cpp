// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/ini_check.hpp"

#include <map>
#include <regex>
#include <set>
#include <sstream>

namespace i20::linuxcnc {
namespace {

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

// "SECTION]KEY" -> the line it is on, for every key of the INI.
std::map<std::string, int> ini_keys(const std::string& text) {
  std::map<std::string, int> keys;
  std::istringstream in(text);
  std::string line, section;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string t = trimmed(line);
    if (t.empty() || t[0] == '#' || t[0] == ';') continue;
    if (t[0] == '[') {
      section = t.substr(1, t.find(']') == std::string::npos ? std::string::npos : t.find(']') - 1);
      continue;
    }
    const auto equals = t.find('=');
    if (equals == std::string::npos || section.empty()) continue;
    keys.emplace("[" + section + "]" + trimmed(t.substr(0, equals)), number);
  }
  return keys;
}

const char* const kNotchKeys[] = {"NOTCH_N0", "NOTCH_N1", "NOTCH_N2", "NOTCH_D1", "NOTCH_D2"};

}  // namespace

std::vector<LintFinding> check_ini(const std::vector<Statement>& statements, const std::string& ini_text,
                                   const std::string& ini_file) {
  const auto keys = ini_keys(ini_text);
  static const std::regex kReference(R"(\[([A-Za-z0-9_]+)\]([A-Za-z0-9_]+))");
  std::vector<LintFinding> findings;
  std::set<std::string> read;
  for (const auto& s : statements)
    for (const auto& arg : s.args)
      for (auto it = std::sregex_iterator(arg.begin(), arg.end(), kReference); it != std::sregex_iterator();
           ++it) {
        const std::string reference = (*it)[0].str();
        read.insert(reference);
        if (keys.count(reference)) continue;
        findings.push_back(
            {s.at, LintSeverity::Error, "ini-missing",
             reference + " is not in " + ini_file + ": halcmd says \"Ini variable '" + reference +
                 "' not found.\" (halcmd refuses this line)",
             "add " + (*it)[2].str() + " = VALUE under [" + (*it)[1].str() + "] in " + ini_file, true});
      }
  for (const auto& [key, line] : keys) {
    const std::string suffix = "]NOTCH_N0";
    if (key.size() <= suffix.size() || key.compare(key.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string section = key.substr(0, key.size() - suffix.size() + 1);  // "[JOINT_k]"
    bool any = false;
    for (const char* k : kNotchKeys) any = any || read.count(section + k) > 0;
    if (any) continue;
    findings.push_back(
        {{ini_file, line},
         LintSeverity::Warning,
         "ini-notch-not-run",
         section + " has a notch (NOTCH_N0..NOTCH_D2, from i20 pid --notch) that no HAL line reads: "
                   "its gains were designed with the notch, and LinuxCNC would run them without it",
         "write the HAL with i20 hal --notch, or design the gains without --notch and drop the "
         "NOTCH_ keys"});
  }
  return findings;
}

}  // namespace i20::linuxcnc
