// SPDX-License-Identifier: GPL-2.0-or-later
// Inside PassthroughPort (passthrough_port.hpp), shared by its two translation units:
// passthrough_port.cpp (the port's lifecycle) and passthrough_packing.cpp (packing rounds
// into packets, running them, replaying after a late DOIT). Not for other users.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "eth/passthrough_port.hpp"
#include "lbp16/lbp16.hpp"

namespace i20::eth {

// What both translation units use: `using namespace passthrough_detail;` there.
namespace passthrough_detail {

namespace lbp16 = lbp::lbp16;
namespace sslbp = lbp::hm2::sslbp;
using std::chrono::microseconds;

// Setup mode's serial rate when the firmware does not say (8I20 setup mode: 115200 8N1).
inline constexpr std::uint32_t kFallbackBaud = 115200;

inline std::uint8_t bit(unsigned channel) {
  return static_cast<std::uint8_t>(1u << channel);
}

inline std::vector<unsigned> channels_of(std::uint8_t mask) {
  std::vector<unsigned> out;
  for (unsigned ch = 0; ch < kMaxChannels; ++ch)
    if (mask & bit(ch)) out.push_back(ch);
  return out;
}

}  // namespace passthrough_detail

// ---- the working state of one execute() -------------------------------------------------

struct PassthroughPort::Channel {
  unsigned channel = 0;
  std::span<const lbp::Command> commands{};
  std::vector<PassthroughStep> steps{};
  // NV access mode each step runs in (nullopt: not known); one more entry for "after".
  std::vector<std::optional<std::uint8_t>> mode_before{};
  std::vector<lbp::Bytes> replies{};  // of steps [0, next)
  std::size_t next = 0;
  bool failed = false;
  std::exception_ptr error{};
  std::optional<std::size_t> failed_transfer{};  // step whose DATA bit was set: CS still to read
  std::optional<std::string> unsupported{};      // why command steps.size() cannot travel

  bool active() const { return !failed && next < steps.size(); }
};

struct PassthroughPort::Slot {
  std::size_t owner = 0;            // index into the execute's channels
  std::optional<std::size_t> step;  // the owner's step; nullopt for an NV mode restore
  PassthroughStep plan{};
  std::optional<std::uint8_t> mode{};  // NV access mode the step runs in
};

struct PassthroughPort::Round {
  std::vector<Slot> slots{};  // ascending channel numbers
  std::uint8_t mask = 0;
  std::chrono::microseconds settle{0};
  std::chrono::microseconds serial{0};
  bool alone = false;        // the only round of its packet
  bool ends_packet = false;  // nothing may follow it in the packet
  std::vector<lbp::lbp16::Command> commands{};
  std::size_t command_read = 0;  // index of the COMMAND read in `commands` (DATA follows)
  // INTERFACE0 reads: index in `commands`, and the slots it serves in channel order.
  std::vector<std::pair<std::size_t, std::vector<std::size_t>>> interface0_reads{};
  std::size_t request_bytes = 0, reply_bytes = 0;
};

struct PassthroughPort::PacketResult {
  enum class Next { Continue, Replay, Resend };
  Next next = Next::Continue;
  std::optional<Round> restore{};  // run alone before the replay
  bool slow = false;               // the replay's first round goes alone (a late DOIT)
};

}  // namespace i20::eth
