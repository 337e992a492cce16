// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/doctor/doctor.hpp"

#include <yaml-cpp/yaml.h>

#include <map>
#include <set>
#include <tuple>

#include "params/yaml_problem.hpp"

namespace i20::doctor {
namespace {

[[noreturn]] void reject(const std::string& where, const std::string& problem) {
  throw BookError(where + ": " + problem);
}

std::string where(const std::string& origin, const YAML::Node& node) {
  return origin + ":" + std::to_string(node.Mark().line + 1);
}

std::string text(const std::string& origin, const YAML::Node& parent, const char* key, bool required = true) {
  const auto node = parent[key];
  if (!node) {
    if (required) reject(where(origin, parent), std::string("'") + key + "' is missing");
    return {};
  }
  if (!node.IsScalar()) reject(where(origin, node), std::string("'") + key + "' must be a string");
  return node.as<std::string>();
}

std::regex compile(const std::string& origin, const YAML::Node& node, const std::string& pattern,
                   std::regex::flag_type extra = {}) {
  try {
    return std::regex(pattern, std::regex::ECMAScript | std::regex::optimize | extra);
  } catch (const std::regex_error& e) {
    reject(where(origin, node), "pattern '" + pattern + "' is not a regular expression: " + e.what());
  }
}

Severity severity(const std::string& origin, const YAML::Node& node, const std::string& s) {
  if (s == "error") return Severity::Error;
  if (s == "warning") return Severity::Warning;
  if (s == "note") return Severity::Note;
  reject(where(origin, node), "severity '" + s + "' is none of error, warning, note");
}

Rule read_rule(const std::string& origin, const YAML::Node& r) {
  Rule rule;
  rule.id = text(origin, r, "id");
  const std::string kind = text(origin, r, "kind");
  if (kind != "finding" && kind != "known")
    reject(where(origin, r), "kind '" + kind + "' is neither finding nor known");
  rule.known = kind == "known";
  rule.pattern = text(origin, r, "pattern");
  rule.re = compile(origin, r, rule.pattern);
  if (rule.known) return rule;
  rule.severity = severity(origin, r, text(origin, r, "severity"));
  rule.title = text(origin, r, "title");
  rule.evidence = text(origin, r, "evidence");
  rule.cause = text(origin, r, "cause");
  rule.said_by = text(origin, r, "said_by");
  rule.docs = text(origin, r, "docs");
  if (rule.docs.rfind("docs/field-messages.md#", 0) != 0)
    reject(where(origin, r),
           "docs must name a section of docs/field-messages.md (docs/field-messages.md#...)");
  const auto fix = r["fix"];
  if (!fix || !fix.IsSequence() || fix.size() == 0)
    reject(where(origin, r), "'fix' must list at least one step");
  for (const auto& step : fix) {
    if (!step.IsScalar())
      reject(where(origin, step), "a fix step must be one string (quote a step with ': ')");
    rule.fix.push_back(step.as<std::string>());
  }
  return rule;
}

// "{1}" ... "{9}" replaced by the match's groups (an unmatched group is empty).
std::string fill(const std::string& templ, const std::smatch& m) {
  std::string out;
  for (std::size_t i = 0; i < templ.size(); ++i) {
    if (templ[i] == '{' && i + 2 < templ.size() && templ[i + 1] >= '0' && templ[i + 1] <= '9' &&
        templ[i + 2] == '}') {
      const auto group = static_cast<std::size_t>(templ[i + 1] - '0');
      if (group < m.size()) out += m[group].str();
      i += 2;
      continue;
    }
    out += templ[i];
  }
  return out;
}

}  // namespace

const char* to_string(Severity s) {
  switch (s) {
    case Severity::Error: return "error";
    case Severity::Warning: return "warning";
    case Severity::Note: return "note";
  }
  return "error";
}

MessageBook MessageBook::load_string(const std::string& yaml, const std::string& origin) {
  const auto root = params::load_yaml(yaml, origin, [](const std::string& at, const std::string& problem) {
    throw BookError(at + ": " + problem);
  });
  MessageBook book;
  try {
    book.watch_ = compile(origin, root, text(origin, root, "watch"), std::regex::icase);
    const auto rules = root["rules"];
    if (!rules || !rules.IsSequence()) reject(origin, "'rules' must be a list");
    std::set<std::string> ids;
    for (const auto& r : rules) {
      auto rule = read_rule(origin, r);
      if (!ids.insert(rule.id).second) reject(where(origin, r), "id '" + rule.id + "' is used twice");
      book.rules_.push_back(std::move(rule));
    }
  } catch (const YAML::Exception& e) {
    throw BookError(origin + ": " + params::yaml_problem(e));
  }
  return book;
}

const Rule* MessageBook::match(const std::string& line, std::smatch& groups) const {
  for (const auto& rule : rules_)
    if (std::regex_search(line, groups, rule.re)) return &rule;
  return nullptr;
}

bool MessageBook::watched(const std::string& line) const {
  return std::regex_search(line, watch_);
}

std::size_t Diagnosis::problems() const {
  std::size_t n = 0;
  for (const auto& f : findings) n += f.severity != Severity::Note;
  return n;
}

std::vector<LogLine> split_lines(const std::string& text, const std::string& file) {
  std::vector<LogLine> lines;
  std::size_t start = 0, number = 0;
  while (start < text.size()) {
    auto end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back({file, ++number, std::move(line)});
    start = end + 1;
  }
  return lines;
}

Diagnosis diagnose(const std::vector<LogLine>& lines, const MessageBook& book) {
  Diagnosis d;
  std::map<std::pair<std::string, std::string>, std::size_t> finding_at;  // (id, evidence) -> index
  std::map<std::string, std::size_t> unknown_at;
  std::smatch m;
  for (const auto& line : lines) {
    ++d.lines;
    const Rule* rule = book.match(line.text, m);
    if (rule != nullptr && rule->known) {
      ++d.known;
      continue;
    }
    if (rule == nullptr) {
      if (!book.watched(line.text)) continue;
      const auto [it, added] = unknown_at.try_emplace(line.text, d.unrecognised.size());
      if (added) d.unrecognised.push_back({{line.file, line.number, line.text}, 0});
      ++d.unrecognised[it->second].count;
      continue;
    }
    const std::string evidence = fill(rule->evidence, m);
    const auto [it, added] = finding_at.try_emplace({rule->id, evidence}, d.findings.size());
    if (added) {
      Finding f;
      f.id = rule->id;
      f.severity = rule->severity;
      f.title = rule->title;
      f.evidence = evidence;
      f.cause = rule->cause;
      f.said_by = rule->said_by;
      f.docs = rule->docs;
      for (const auto& step : rule->fix) f.fix.push_back(fill(step, m));
      d.findings.push_back(std::move(f));
    }
    auto& f = d.findings[it->second];
    if (f.said.size() < kKeptLines) f.said.push_back({line.file, line.number, line.text});
    ++f.count;
    f.last_file = line.file;
    f.last_line = line.number;
  }
  return d;
}

}  // namespace i20::doctor
