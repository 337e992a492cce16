// SPDX-License-Identifier: GPL-2.0-or-later
// What every fuzz target shares: the contract for bad input and a reader of the fuzzer's
// bytes.
//
// The contract: an i20::Error (or a subclass) is the expected answer to bad input. Any
// other exception escaping (std::out_of_range, YAML::Exception, ...) is a finding, and so
// is a crash, a sanitizer report, a hang or unbounded memory (libFuzzer's -timeout and
// -rss_limit_mb catch those).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>
#include <typeinfo>

#include "lbp/bytes.hpp"
#include "error/error.hpp"

namespace i20::fuzz {

// Ends the run with the foreign exception's type and message, so the report says what escaped.
[[noreturn]] inline void foreign(const char* type, const char* what) {
  std::fprintf(stderr, "FINDING: a foreign exception escaped: %s: %s\n", type, what);
  std::abort();
}

// Runs `f` on one input; the toolkit's own errors are fine, anything else aborts.
template <typename F>
void expect_only_toolkit_errors(F&& f) {
  try {
    f();
  } catch (const i20::Error&) {
    // The expected answer to bad input.
  } catch (const std::exception& e) {
    foreign(typeid(e).name(), e.what());
  } catch (...) {
    foreign("(not a std::exception)", "");
  }
}

// Runs `f`, which must not throw at all (the simulators answer any bytes on the line).
template <typename F>
void expect_no_exception(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    foreign(typeid(e).name(), e.what());
  } catch (...) {
    foreign("(not a std::exception)", "");
  }
}

// An invariant the target checks beyond "no crash": a wrong answer is a finding too.
inline void require(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "FINDING: invariant broken: %s\n", what);
  std::abort();
}

// Consumes the fuzzer's bytes front to back; past the end everything reads as zero.
class Input {
 public:
  Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool empty() const { return pos_ >= size_; }
  std::size_t remaining() const { return size_ - pos_; }
  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::uint16_t u16() {
    const std::uint16_t lo = byte();
    return static_cast<std::uint16_t>(lo | (byte() << 8));
  }
  // Up to n bytes (fewer at the end).
  lbp::Bytes take(std::size_t n) {
    n = std::min(n, remaining());
    lbp::Bytes out(data_ + pos_, data_ + pos_ + n);
    pos_ += n;
    return out;
  }
  lbp::Bytes rest() { return take(remaining()); }
  std::string rest_text() {
    const auto b = rest();
    return std::string(b.begin(), b.end());
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

inline std::string_view text_of(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace i20::fuzz
