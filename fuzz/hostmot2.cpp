// SPDX-License-Identifier: GPL-2.0-or-later
// HostMot2 identification (docs/facts.md s5; 7I96S/7I92T manuals, "HOSTMOT2"): the
// IDROM, module and pin parsers and SSERIAL register location, directly and through
// discovery (eth::read_hostmot2) against a card whose space 0 reads are the fuzzer's
// bytes in the order discovery asks for them (ident area, IDROM, modules, pins).
#include "hostmot2/hostmot2.hpp"

#include <cstddef>
#include <cstdint>

#include "eth/anything_io.hpp"
#include "eth/transport.hpp"
#include "fuzz_support.hpp"

namespace {

using namespace i20;
namespace hm2 = lbp::hm2;

// A card that answers every read with the next bytes of the input (zeros once it runs out).
class FuzzedCard final : public eth::Lbp16Transport {
 public:
  explicit FuzzedCard(fuzz::Input& in) : in_(in) {}
  std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands, eth::Resend) override {
    std::vector<lbp::Bytes> out;
    for (const auto& c : commands) {
      lbp::Bytes data = in_.take(c.reply_bytes());
      data.resize(c.reply_bytes(), 0);
      out.push_back(std::move(data));
    }
    return out;
  }
  std::string describe() const override { return "fuzzed card"; }
  eth::TransportStats stats() const override { return {}; }

 private:
  fuzz::Input& in_;
};

void discover(fuzz::Input& in) {
  FuzzedCard card(in);
  const auto info = eth::read_hostmot2(card);
  fuzz::require(info.ident.valid(), "discovery accepts only the HostMot2 cookie");
  fuzz::require(info.modules.size() <= hm2::kMaxModules, "at most kMaxModules modules");
  fuzz::require(info.pins.size() <= hm2::kMaxPins, "at most kMaxPins pins");
  const auto ports = info.sserial_ports();
  for (const auto& p : ports) {
    for (unsigned ch = 0; ch < hm2::kMaxChannelsPerPort; ++ch) {
      (void)p.registers.cs(ch);
      (void)p.registers.interface0(ch);
    }
  }
  // The first port, and the first that does not exist (each call lists every port again).
  for (const auto i : {std::size_t{0}, ports.size()})
    (void)eth::find_sserial_port(info, static_cast<unsigned>(i));
}

void parsers(lbp::ByteView bytes) {
  fuzz::expect_only_toolkit_errors([&] { (void)hm2::IdentArea::parse(bytes); });
  fuzz::expect_only_toolkit_errors([&] { (void)hm2::Idrom::parse(bytes); });
  const auto modules = hm2::parse_modules(bytes);
  fuzz::require(modules.size() <= hm2::kMaxModules, "parse_modules stops at kMaxModules");
  fuzz::expect_only_toolkit_errors([&] { (void)hm2::parse_pins(bytes, bytes.size() / 4); });
  if (bytes.size() < hm2::Idrom::kBytes) return;
  const auto idrom = hm2::Idrom::parse(bytes.first(hm2::Idrom::kBytes));
  for (const auto& m : hm2::parse_modules(bytes.subspan(hm2::Idrom::kBytes))) {
    fuzz::require(hm2::ModuleDescriptor::parse(m.encode()) == m, "a module descriptor round-trips");
    for (unsigned i = 0; i < m.instances && i < 4; ++i) {
      fuzz::expect_only_toolkit_errors([&] { (void)hm2::SserialRegisters::locate(idrom, m, i); });
      for (unsigned r = 0; r < m.registers && r < 8; ++r)
        fuzz::expect_only_toolkit_errors([&] {
          fuzz::require(m.register_address(idrom, r, i) <= 0xFFFC, "a register address stays in space 0");
        });
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  fuzz::expect_only_toolkit_errors([&] { discover(in); });
  fuzz::expect_only_toolkit_errors([&] { parsers(lbp::ByteView(data, size)); });
  return 0;
}
