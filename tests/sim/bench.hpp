// SPDX-License-Identifier: GPL-2.0-or-later
// A virtual 8I20 on the test bench: raw bytes in, raw bytes out, and a clock the test
// moves by hand. Commands are written as hex from the manual's tables; the CRC is added
// by lbp::crc8 so that what goes on the wire is exactly what a host would send.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <string_view>

#include "lbp/bytes.hpp"
#include "lbp/crc8.hpp"
#include "sim/virtual_8i20.hpp"

namespace i20::sim::test {

using namespace std::chrono_literals;

inline const Clock::time_point kT0 = Clock::time_point{} + std::chrono::hours(1);

// "45 08 08" -> 45 08 08 + CRC-8.
inline lbp::Bytes framed(std::string_view hex) {
  lbp::Bytes b = lbp::from_hex(std::string(hex));
  b.push_back(lbp::crc8(b));
  return b;
}

// What the card sends back for reply data `hex` (data + CRC); "" -> the lone 0x00.
inline lbp::Bytes reply(std::string_view hex) {
  return framed(hex);
}

inline lbp::Bytes cat(std::initializer_list<lbp::Bytes> parts) {
  lbp::Bytes out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

class Bench {
 public:
  explicit Bench(DeviceOptions options = {}) : card(std::move(options), t) {}

  // Sends one command (hex without CRC) at the current time; returns what came back.
  lbp::Bytes send(std::string_view hex) { return raw(framed(hex)); }
  lbp::Bytes raw(const lbp::Bytes& wire) {
    card.receive(wire, t);
    return card.take_output();
  }
  // Lets time pass; returns what the card sent meanwhile.
  lbp::Bytes wait(Clock::duration d) {
    t += d;
    card.advance(t);
    return card.take_output();
  }

  // Reads `bytes` (1, 2, 4, 8) at `address` and returns the value, checking the reply's CRC.
  std::uint64_t read(std::uint16_t address, unsigned bytes = 2) {
    const lbp::Byte size = bytes == 1 ? 0 : bytes == 2 ? 1 : bytes == 4 ? 2 : 3;
    const lbp::Bytes cmd{static_cast<lbp::Byte>(0x44 | size), static_cast<lbp::Byte>(address),
                         static_cast<lbp::Byte>(address >> 8)};
    lbp::Bytes wire = cmd;
    wire.push_back(lbp::crc8(cmd));
    const lbp::Bytes out = raw(wire);
    EXPECT_EQ(out.size(), bytes + 1u) << "read at " << address;
    if (out.size() != bytes + 1u) return ~0ull;
    EXPECT_EQ(out.back(), lbp::crc8(lbp::ByteView(out).first(bytes)));
    return lbp::read_le(lbp::ByteView(out).first(bytes));
  }
  // Writes a 16-bit value at `address`; returns the reply bytes.
  lbp::Bytes write16(std::uint16_t address, std::uint16_t value) {
    const lbp::Bytes cmd{0x65, static_cast<lbp::Byte>(address), static_cast<lbp::Byte>(address >> 8),
                         static_cast<lbp::Byte>(value), static_cast<lbp::Byte>(value >> 8)};
    lbp::Bytes wire = cmd;
    wire.push_back(lbp::crc8(cmd));
    return raw(wire);
  }
  // One local read (0xC0..0xDF) -> its data byte.
  lbp::Byte local(lbp::Byte command) {
    const lbp::Bytes out = raw(lbp::Bytes{command, lbp::crc8(lbp::Bytes{command})});
    EXPECT_EQ(out.size(), 2u) << "local read " << int(command);
    return out.empty() ? 0xEE : out[0];
  }
  std::uint16_t address_of(std::string_view name) const { return card.amplifier().map().at(name).address; }
  std::uint64_t read(std::string_view name) {
    const auto& r = card.amplifier().map().at(name);
    return read(r.address, r.bytes());
  }

  Clock::time_point t = kT0;
  Virtual8i20 card;
};

}  // namespace i20::sim::test
