// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/anything_io.hpp"

#include <algorithm>

#include "eth/errors.hpp"
#include "lbp/bytes.hpp"

namespace i20::eth {

namespace lbp16 = lbp::lbp16;
namespace hm2 = lbp::hm2;

namespace {

struct Block {
  std::uint32_t address = 0;
  std::size_t bytes = 0;
};

// Reads blocks of space 0 in 32-bit words, all in one packet; a block longer than 127
// words takes several commands.
std::vector<lbp::Bytes> read_blocks(Lbp16Transport& bus, std::initializer_list<Block> blocks) {
  std::vector<lbp16::Command> commands;
  std::vector<std::size_t> commands_per_block;
  for (const Block& b : blocks) {
    if (b.address + b.bytes > 0x10000) throw DiscoveryError("HostMot2 IDROM points outside space 0");
    std::size_t count = 0;
    for (std::size_t done = 0; done < b.bytes; ++count) {
      const std::size_t words = std::min<std::size_t>((b.bytes - done + 3) / 4, lbp16::kMaxCount);
      commands.push_back(
          lbp16::read_hm2(static_cast<std::uint16_t>(b.address + done), static_cast<unsigned>(words)));
      done += 4 * words;
    }
    commands_per_block.push_back(count);
  }
  const auto parts = bus.transact(commands);
  std::vector<lbp::Bytes> out;
  std::size_t next = 0;
  auto block = blocks.begin();
  for (std::size_t count : commands_per_block) {
    lbp::Bytes data;
    for (std::size_t i = 0; i < count; ++i, ++next)
      data.insert(data.end(), parts[next].begin(), parts[next].end());
    data.resize((block++)->bytes);
    out.push_back(std::move(data));
  }
  return out;
}

lbp::Bytes read_block(Lbp16Transport& bus, std::uint32_t address, std::size_t bytes) {
  return read_blocks(bus, {Block{address, bytes}}).front();
}

}  // namespace

BoardIdentity identify(Lbp16Transport& bus) {
  const lbp16::Command command = lbp16::read_board_info();
  const auto info = lbp16::BoardInfo::parse(bus.transact(std::span(&command, 1)).front());
  return BoardIdentity{.card_name = info.card_name,
                       .lbp16_version = info.lbp16_version,
                       .firmware_version = info.firmware_version};
}

const hm2::ModuleDescriptor* HostMot2Info::find(std::uint8_t gtag) const {
  const auto it = std::find_if(modules.begin(), modules.end(), [&](const auto& m) { return m.gtag == gtag; });
  return it == modules.end() ? nullptr : &*it;
}

std::vector<SserialPort> HostMot2Info::sserial_ports() const {
  std::vector<SserialPort> out;
  for (const auto& m : modules) {
    if (!hm2::is_sserial(m.gtag)) continue;
    for (unsigned i = 0; i < m.instances; ++i)
      out.push_back(SserialPort{.index = static_cast<unsigned>(out.size()),
                                .gtag = m.gtag,
                                .version = m.version,
                                .registers = hm2::SserialRegisters::locate(idrom, m, i)});
  }
  return out;
}

HostMot2Info read_hostmot2(Lbp16Transport& bus) {
  HostMot2Info info;
  info.ident = hm2::IdentArea::parse(read_block(bus, hm2::kCookieAddress, 16));
  if (!info.ident.valid())
    throw DiscoveryError("no HostMot2 configuration on " + bus.describe() + ": cookie at 0x0100 reads " +
                         lbp::hex_value(info.ident.cookie, 8) +
                         ", expected 0x55AACAFE (is the FPGA configured?)");
  if (info.ident.idrom_address == 0 || info.ident.idrom_address > 0xFFFF - hm2::Idrom::kBytes)
    throw DiscoveryError("HostMot2 IDROM pointer " + lbp::hex_value(info.ident.idrom_address, 8) + " on " +
                         bus.describe() + " is outside space 0");
  info.idrom = hm2::Idrom::parse(read_block(bus, info.ident.idrom_address, hm2::Idrom::kBytes));

  const std::uint32_t modules_at = info.ident.idrom_address + info.idrom.offset_to_modules;
  const std::uint32_t pins_at = info.ident.idrom_address + info.idrom.offset_to_pins;
  const std::size_t pin_count = std::min<std::size_t>(info.idrom.io_width, hm2::kMaxPins);
  const auto tables = read_blocks(bus, {Block{modules_at, hm2::kMaxModules * hm2::ModuleDescriptor::kBytes},
                                        Block{pins_at, pin_count * hm2::PinDescriptor::kBytes}});
  info.modules = hm2::parse_modules(tables[0]);
  info.pins = hm2::parse_pins(tables[1], pin_count);
  return info;
}

SserialPort find_sserial_port(const HostMot2Info& info, unsigned index) {
  const auto ports = info.sserial_ports();
  if (ports.empty())
    throw DiscoveryError(
        "the " + info.idrom.board_name +
        " configuration has no SSERIAL module (GTag 0xC1/0xC6): load firmware with smart serial");
  if (index >= ports.size())
    throw DiscoveryError("the " + info.idrom.board_name + " configuration has " +
                         std::to_string(ports.size()) + " SSERIAL port(s), there is no port " +
                         std::to_string(index));
  return ports[index];
}

}  // namespace i20::eth
