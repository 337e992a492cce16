// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual 8I20 (lib/sim) fed arbitrary bytes with arbitrary gaps, in setup mode
// (pre-parse framing) or operate mode (timing framing), with or without fault
// injection. The card answers any bytes on the line, so nothing may throw; and it must
// never livelock (an event due at or before the time just processed would make i20sim
// spin).
//
// Input: [flags][seed][event byte, bytes]...; an event byte's low 5 bits + 1 are the
// number of bytes sent, its high 3 bits pick the gap before them.
#include <chrono>
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "sim/virtual_8i20.hpp"

namespace {

using namespace i20;
using namespace std::chrono_literals;
using sim::Clock;

sim::DeviceOptions options(std::uint8_t flags, std::uint8_t seed) {
  sim::DeviceOptions o;
  o.mode = (flags & 0x01) ? sim::FramingMode::Operate : sim::FramingMode::Setup;
  if (flags & 0x02) o.injection.eeprom_power_loss = sim::EepromPowerLoss::Torn;
  if (flags & 0x04) o.injection.eeprom_power_loss = sim::EepromPowerLoss::Lost;
  if (flags & 0x08) o.injection.reset_after_commands = seed % 16 + 1;
  if (flags & 0x10) o.injection.corrupt_rate = 0.05;
  if (flags & 0x20) o.injection.drop_rate = 0.05;
  if (flags & 0x40) o.injection.answer_limit = seed % 8;
  if (flags & 0x80) o.rx_buffer_bytes = 16;
  o.injection.seed = seed;
  o.reset_time = (seed & 1) ? Clock::duration::zero() : Clock::duration(1ms);
  return o;
}

Clock::duration gap(unsigned pick, Clock::duration character) {
  switch (pick) {
    case 0: return Clock::duration::zero();
    case 1: return character;
    case 2: return character * 10;
    case 3: return character * 30;  // past the default command timeout of 25.5 characters
    case 4: return 2500us;          // an EEPROM word write
    case 5: return 10ms;
    case 6: return 50ms;  // past the operate-mode watchdog
    default: return 1s;
  }
}

// Lets the card run its pending events up to `until`, and checks each one moves time on.
void run_events(sim::Virtual8i20& card, Clock::time_point& now, Clock::time_point until) {
  for (int i = 0; i < 64; ++i) {
    const auto next = card.next_event();
    if (!next || *next > until) break;
    fuzz::require(*next > now || i == 0, "the next event is later than the one just processed");
    now = std::max(now, *next);
    card.advance(now);
    (void)card.take_output();
  }
  now = std::max(now, until);
  card.advance(now);
}

void run(fuzz::Input& in) {
  const std::uint8_t flags = in.byte();
  const std::uint8_t seed = in.byte();
  Clock::time_point now{};
  const sim::DeviceOptions o = options(flags, seed);
  sim::Virtual8i20 card(o, now);
  std::size_t sent = 0, received = 0;
  while (!in.empty()) {
    const std::uint8_t event = in.byte();
    run_events(card, now, now + gap(event >> 5, card.character_time()));
    const lbp::Bytes bytes = in.take((event & 0x1F) + 1u);
    card.receive(bytes, now);
    sent += bytes.size();
    received += card.take_output().size();
    fuzz::require(card.rx_pending() <= o.rx_buffer_bytes, "the receive buffer holds at most its capacity");
    if (!card.powered() && (seed & 2)) card.power_cycle(now);  // bring it back, as `power cycle` does
  }
  run_events(card, now, now + 2s);
  received += card.take_output().size();
  // Every reply answers a command of at least one byte; an RPC's reply is at most the table.
  fuzz::require(received <= (card.stats().commands_executed + 1) * 520, "replies answer commands");
  (void)sent;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  fuzz::expect_no_exception([&] { run(in); });
  return 0;
}
