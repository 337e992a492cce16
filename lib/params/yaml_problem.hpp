// SPDX-License-Identifier: GPL-2.0-or-later
// The reason yaml-cpp gave for rejecting a file, in words a user can act on. Shared by the
// loaders of parameter overlays, profiles and fault tables.
#pragma once

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>
#include <yaml-cpp/yaml.h>

#include <sstream>
#include <stdexcept>
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

// What a pass over a YAML stream's documents saw, without building nodes: whether a
// document after the first holds anything, and whether the parser stopped advancing.
// yaml-cpp 0.7's own LoadAll loops for ever on some broken input (a stray ',' makes every
// "next document" an empty one at the same place), so documents are walked here, with a
// guard, instead.
class DocumentWalk final : public YAML::EventHandler {
 public:
  struct Finding {
    enum class Kind { None, SecondDocument, Stuck } kind = Kind::None;
    int line = 0;  // 0-based, as yaml-cpp counts
  };

  static Finding walk(const std::string& yaml) {
    std::istringstream in(yaml);
    YAML::Parser parser(in);
    DocumentWalk walk;
    for (int index = 0;; ++index) {
      walk.content_ = false;
      walk.null_at_ = -1;
      if (!parser.HandleNextDocument(walk)) return {};
      if (index > 0 && walk.content_) return {Finding::Kind::SecondDocument, walk.content_line_};
      // An empty document that starts where the last one did: the parser cannot read on.
      if (!walk.content_ && walk.null_at_ >= 0 && walk.null_at_ == walk.last_null_at_)
        return {Finding::Kind::Stuck, walk.start_line_};
      walk.last_null_at_ = walk.null_at_;
    }
  }

  void OnDocumentStart(const YAML::Mark& mark) override { start_line_ = mark.line; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override {
    if (!content_) null_at_ = mark.pos;
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { content_at(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t, const std::string&) override {
    content_at(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    content_at(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    content_at(mark);
  }
  void OnMapEnd() override {}

 private:
  // The first node of a document: where a second document is reported.
  void content_at(const YAML::Mark& mark) {
    if (content_) return;
    content_ = true;
    content_line_ = mark.line;
  }

  bool content_ = false;
  int content_line_ = 0;
  int start_line_ = 0;
  int null_at_ = -1;
  int last_null_at_ = -2;
};

// Parses `yaml` read from `source`. A syntax error goes to `fail("SOURCE:LINE", problem)`,
// which throws the loader's own error type.
// A file holds one document: a second one after `---` (even a broken one) is refused, not
// silently dropped, so nothing a user wrote goes unread.
template <class Fail>
YAML::Node load_yaml(std::string_view yaml, const std::string& source, Fail&& fail) {
  const std::string text(yaml);
  const auto where = [&](int line) { return source + ":" + std::to_string(line >= 0 ? line + 1 : 1); };
  YAML::Node first;
  DocumentWalk::Finding finding;
  try {
    finding = DocumentWalk::walk(text);
    first = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    fail(where(e.mark.line), yaml_problem(e));
    throw;  // only if `fail` did not throw
  }
  using Kind = DocumentWalk::Finding::Kind;
  if (finding.kind == Kind::SecondDocument)
    fail(
        where(finding.line),
        "a second YAML document (after ---): a file holds one; split it into files, or remove the extra one");
  if (finding.kind == Kind::Stuck)
    fail(where(finding.line),
         "not valid YAML: the parser cannot read past this line (a stray ',' or similar)");
  if (finding.kind != Kind::None) throw std::logic_error("load_yaml: fail() returned");
  return first;
}

}  // namespace i20::params
