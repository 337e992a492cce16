// SPDX-License-Identifier: GPL-2.0-or-later
// A count or a wait that the caller must give. The layers below ops hold no retry count and
// no timeout of their own: every such figure in their option structs is a Given, which has
// no default, so an options struct built without it does not compile (aggregate
// initialisation that leaves a Given out is an error, and so is a default-constructed
// struct). The programs build the structs in ops/core/timing.hpp; a test names its figures or
// takes the programs' from there.
#pragma once

#include <chrono>
#include <concepts>

namespace i20::link {

template <class T>
class Given;

// A duration: it is one (std::chrono's arithmetic, comparisons and casts take it as it is).
template <class Rep, class Period>
class Given<std::chrono::duration<Rep, Period>> : public std::chrono::duration<Rep, Period> {
 public:
  using Duration = std::chrono::duration<Rep, Period>;
  template <class Rep2, class Period2>
  requires std::convertible_to<std::chrono::duration<Rep2, Period2>, Duration>
  constexpr Given(std::chrono::duration<Rep2, Period2> value) : Duration(value) {}
  constexpr Duration get() const { return *this; }
};

// A count: reads as the number it holds.
template <std::unsigned_integral T>
class Given<T> {
 public:
  constexpr Given(T value) : value_(value) {}
  constexpr operator T() const { return value_; }
  constexpr T get() const { return value_; }

 private:
  T value_;
};

}  // namespace i20::link
