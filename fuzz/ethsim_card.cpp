// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual 7I96S/7I92T (lib/ethsim) fed arbitrary UDP payloads: LBP16 to every space,
// HostMot2 registers, SSLBP commands and the virtual 8I20s behind them. Like the real
// card it answers (or ignores) any payload; nothing may throw, and a reply is never
// larger than the reads the request holds.
//
// Input: [card][8I20 mode][gap, length, payload]...
#include <chrono>
#include <cstddef>
#include <cstdint>

#include "ethsim/virtual_8i20_remote.hpp"
#include "ethsim/virtual_board.hpp"
#include "fuzz_support.hpp"
#include "lbp16/lbp16.hpp"

namespace {

using namespace i20;
using namespace std::chrono_literals;
using ethsim::Clock;

ethsim::VirtualBoardOptions options(std::uint8_t card, std::uint8_t mode) {
  ethsim::VirtualBoardOptions o;
  o.config = ethsim::BoardConfig::preset((card & 1) ? ethsim::BoardKind::I7i92t : ethsim::BoardKind::I7i96s);
  const bool operate = (mode & 1) == 0;
  o.remotes = [operate, mode](unsigned port, unsigned channel) -> std::unique_ptr<ethsim::RemoteLbpDevice> {
    if ((port + channel) % 2 == 1 && (mode & 2)) return nullptr;  // some channels empty
    sim::DeviceOptions d = ethsim::Virtual8i20Remote::default_options();
    d.mode = operate ? sim::FramingMode::Operate : sim::FramingMode::Setup;
    if (mode & 4) d.injection.drop_rate = 0.1;
    return std::make_unique<ethsim::Virtual8i20Remote>(std::move(d), Clock::time_point{});
  };
  return o;
}

Clock::duration gap(std::uint8_t pick) {
  switch (pick % 4) {
    case 0: return 0us;
    case 1: return 100us;
    case 2: return 5ms;
    default: return 100ms;
  }
}

void run(fuzz::Input& in) {
  const std::uint8_t card_pick = in.byte();
  const std::uint8_t mode = in.byte();
  Clock::time_point now{};
  ethsim::VirtualBoard board(options(card_pick, mode), now);
  while (!in.empty()) {
    now += gap(in.byte());
    const lbp::Bytes payload = in.take(in.u16() % (lbp::lbp16::kMaxPayload + 64));
    const auto reply = board.handle(payload, now);
    const auto parsed = lbp::lbp16::parse_request(payload);
    const std::size_t reads = lbp::lbp16::reply_bytes(parsed.commands);
    fuzz::require(reply.has_value() == (reads > 0), "a packet gets a reply exactly when it holds reads");
    if (reply) fuzz::require(reply->size() == reads, "a reply holds exactly the data of the reads executed");
    now = std::max(now, board.board_time());
    board.advance(now);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  fuzz::expect_no_exception([&] { run(in); });
  return 0;
}
