// SPDX-License-Identifier: GPL-2.0-or-later
// A minimal 8I20 stand-in for link tests: 64 KiB of byte-addressed memory behind LBP
// data commands, the address pointer with auto-increment, and a few local commands.
// It only knows what the link tests need; the real simulator lives in lib/sim.
#pragma once

#include <optional>

#include "lbp/bytes.hpp"
#include "lbp/crc8.hpp"
#include "lbp/header.hpp"
#include "lbp/local.hpp"

namespace i20::link::fake {

class FakeCard {
 public:
  FakeCard() : memory_(0x10000, 0) {}

  lbp::Byte& at(std::uint16_t address) { return memory_[address]; }
  void store(std::uint16_t address, lbp::ByteView bytes) {
    for (auto b : bytes) memory_[address++] = b;
  }

  // Reply data (without CRC) to one command; nullopt for commands it does not know.
  std::optional<lbp::Bytes> answer(const lbp::Bytes& command) {
    const auto header = command.at(0);
    switch (lbp::kind_of(header)) {
      case lbp::CommandKind::Data: return data(command);
      case lbp::CommandKind::LocalRead:
        return lbp::Bytes{header == lbp::local::kGetCookie ? lbp::local::kCookie : lbp::Byte{0}};
      case lbp::CommandKind::LocalWrite: return lbp::Bytes{};
      default: return std::nullopt;
    }
  }

  // The reply on the wire: data followed by its CRC (a write's reply is just 0x00).
  static lbp::Bytes wire(const lbp::Bytes& data) {
    lbp::Bytes out = data;
    out.push_back(lbp::crc8(data));
    return out;
  }

 private:
  lbp::Bytes data(const lbp::Bytes& command) {
    const auto h = lbp::DataHeader::decode(command[0]);
    std::size_t offset = 1;
    if (h.has_address) {
      pointer_ = static_cast<std::uint16_t>(command[1] | command[2] << 8);
      offset = 3;
    }
    const auto n = h.data_bytes();
    lbp::Bytes reply;
    for (std::size_t i = 0; i < n; ++i) {
      auto& cell = memory_[static_cast<std::uint16_t>(pointer_ + i)];
      if (h.write)
        cell = command[offset + i];
      else
        reply.push_back(cell);
    }
    if (h.auto_increment) pointer_ = static_cast<std::uint16_t>(pointer_ + n);
    return reply;
  }

  lbp::Bytes memory_;
  std::uint16_t pointer_ = 0;
};

}  // namespace i20::link::fake
