// SPDX-License-Identifier: GPL-2.0-or-later
// The simulator's control language (lib/sim/control: i20sim's stdin and --control FIFO),
// one line at a time, with time passing and a little LBP traffic in between so world
// changes reach the card. A line it does not understand throws ControlError; nothing
// else may escape, and the card keeps answering.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "lbp/command.hpp"
#include "lbp/crc8.hpp"
#include "sim/control.hpp"
#include "sim/virtual_8i20.hpp"

namespace {

using namespace i20;
using namespace std::chrono_literals;
using sim::Clock;

// 0xD4: read LBP status, with its CRC (a command every card state answers or ignores).
lbp::Bytes status_read() {
  lbp::Bytes b{0xD4};
  b.push_back(lbp::crc8(b));
  return b;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = fuzz::text_of(data, size);
  Clock::time_point now{};
  sim::Virtual8i20 card({}, now);
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto end = std::min(text.find('\n', start), text.size());
    const std::string_view line = text.substr(start, end - start);
    start = end + 1;
    fuzz::expect_only_toolkit_errors([&] { (void)sim::apply_control(card, line, now); });
    fuzz::expect_no_exception([&] {
      now += 3ms;
      card.receive(status_read(), now);
      card.advance(now + 1ms);
      (void)card.take_output();
      (void)sim::describe_state(card);
    });
  }
  return 0;
}
