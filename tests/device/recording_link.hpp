// SPDX-License-Identifier: GPL-2.0-or-later
// A Link that plays a minimal 8I20 memory model and records every command it was given,
// so device-layer tests can assert what was (and was not) sent. The full-fidelity device
// is the simulator (lib/sim); this fake keeps these tests independent of it.
#pragma once

#include <array>
#include <vector>

#include "lbp/header.hpp"
#include "lbp/local.hpp"
#include "link/link.hpp"

namespace i20::test {

class FakeCard : public link::Link {
 public:
  std::array<lbp::Byte, 0x10000> ram{};
  std::array<lbp::Byte, 256> eeprom{};
  lbp::Byte nv_mode = 0;
  lbp::Byte rpcmem = 0;
  std::vector<lbp::Command> sent;
  std::vector<std::size_t> exchanges;  // commands per execute() call, in order
  // Fail (throw TimeoutError) on the n-th command from now, counting from 0; -1 never.
  int fail_at = -1;
  // Corrupt what EEPROM writes store (simulates a failing cell).
  bool eeprom_stuck = false;
  // The card resets just before the n-th command from now (counting from 0; -1 never):
  // NV access mode drops back to RAM, as a real reset does.
  int reset_at = -1;

  std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override {
    std::vector<lbp::Bytes> replies;
    exchanges.push_back(batch.size());
    for (const auto& c : batch) {
      if (fail_at == 0) {
        fail_at = -1;
        throw link::TimeoutError("fake timeout", replies.size());
      }
      if (fail_at > 0) --fail_at;
      if (reset_at == 0) nv_mode = 0;
      if (reset_at >= 0) --reset_at;
      sent.push_back(c);
      replies.push_back(run(c));
    }
    return replies;
  }
  std::string describe() const override { return "fake card"; }

  void put(std::uint16_t address, std::uint64_t value, std::size_t bytes, bool nv = false) {
    for (std::size_t i = 0; i < bytes; ++i) mem(nv)[address + i] = static_cast<lbp::Byte>(value >> (8 * i));
  }
  std::uint64_t get(std::uint16_t address, std::size_t bytes, bool nv = false) {
    std::uint64_t v = 0;
    for (std::size_t i = bytes; i-- > 0;) v = (v << 8) | mem(nv)[address + i];
    return v;
  }

 private:
  lbp::Byte* mem(bool nv) { return nv ? eeprom.data() : ram.data(); }

  lbp::Bytes run(const lbp::Command& c) {
    const lbp::Byte h = c.bytes.at(0);
    switch (lbp::kind_of(h)) {
      case lbp::CommandKind::LocalRead:
        if (h == lbp::local::kGetCookie) return {lbp::local::kCookie};
        if (h == lbp::local::kGetNvAccess) return {nv_mode};
        if (h >= 0xD0 && h <= 0xD3) return {static_cast<lbp::Byte>("8I20"[h - 0xD0])};
        return {0};
      case lbp::CommandKind::LocalWrite:
        if (h == lbp::local::kSetNvAccess) nv_mode = c.bytes.at(1);
        if (h == lbp::local::kSetRpcMemAccess) rpcmem = c.bytes.at(1);
        return {};
      case lbp::CommandKind::Data: {
        const auto d = lbp::DataHeader::decode(h);
        const auto address = static_cast<std::uint16_t>(c.bytes.at(1) | (c.bytes.at(2) << 8));
        const bool nv = nv_mode == 1;
        if (d.write) {
          for (std::size_t i = 0; i < d.data_bytes(); ++i)
            mem(nv)[address + i] = (nv && eeprom_stuck) ? 0xFF : c.bytes.at(3 + i);
          return {};
        }
        return lbp::Bytes(mem(nv) + address, mem(nv) + address + d.data_bytes());
      }
      default: return {};
    }
  }
};

}  // namespace i20::test
