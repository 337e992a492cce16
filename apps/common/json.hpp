// SPDX-License-Identifier: GPL-2.0-or-later
// A minimal JSON value for --json output (objects keep insertion order, so output is
// stable and diffable). Only what the apps print; not a parser.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace i20::app {

class Json {
 public:
  using Array = std::vector<Json>;
  using Object = std::vector<std::pair<std::string, Json>>;

  Json() : value_(nullptr) {}
  Json(std::nullptr_t) : value_(nullptr) {}
  Json(bool b) : value_(b) {}
  Json(int v) : value_(static_cast<std::int64_t>(v)) {}
  Json(unsigned v) : value_(static_cast<std::int64_t>(v)) {}
  Json(long v) : value_(static_cast<std::int64_t>(v)) {}
  Json(long long v) : value_(static_cast<std::int64_t>(v)) {}
  Json(unsigned long v) : value_(static_cast<std::int64_t>(v)) {}
  Json(unsigned long long v) : value_(static_cast<std::int64_t>(v)) {}
  Json(double v) : value_(v) {}
  Json(const char* s) : value_(std::string(s)) {}
  Json(std::string s) : value_(std::move(s)) {}
  Json(Array a) : value_(std::move(a)) {}
  Json(Object o) : value_(std::move(o)) {}

  static Json object() { return Json(Object{}); }
  static Json array() { return Json(Array{}); }

  // Appends a key to an object (the value must be an object).
  Json& set(std::string key, Json value);
  // Appends to an array (the value must be an array).
  Json& push(Json value);

  std::string dump(int indent = 2) const;

  // The value itself, for a writer of another format (the --yaml of a report built as Json).
  using Value = std::variant<std::nullptr_t, bool, std::int64_t, double, std::string, Array, Object>;
  const Value& value() const { return value_; }

 private:
  void write(std::string& out, int indent, int depth) const;
  Value value_;
};

}  // namespace i20::app
