// SPDX-License-Identifier: GPL-2.0-or-later
// What the virtual card looks like from the network: its name and versions (space 7),
// Ethernet EEPROM contents (space 2) and the HostMot2 configuration it presents (IDROM,
// modules, pins, SSERIAL ports). Two presets:
//
//  7I96S: one SSERIAL port with one channel (the RS-422 port on TB2), step/dir, encoder,
//         InM (the 11 isolated inputs) and GPIO modules on 51 pins, laid out like firmware
//         7i96s_d as LinuxCNC's PnCconf describes it (docs/virtual-feedback.md).
//  7I92T: two SSERIAL ports of eight channels (a 7I74X2D-style configuration: one 8-channel
//         RS-422 daughter card per connector, e.g. 7I44/7I74), 34 pins.
//  7I92T servo (preset_7i92t_servo): four axes, each with an encoder, an RS-422 SSERIAL
//         channel for its 8I20 and three GPIO Hall inputs, in the manner of the 7I85S
//         firmwares; our own layout, not a Mesa bitfile.
//
// Version numbers and the IDROM board name are simulation values: close to what real
// cards report, not copied from a real bitfile.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "hostmot2/hostmot2.hpp"

namespace i20::ethsim {

enum class BoardKind { I7i96s, I7i92t };

// "7i96s"/"7I96S" or "7i92t"/"7I92T". Throws UsageError on anything else.
BoardKind parse_board_kind(std::string_view text);
std::string_view board_kind_name(BoardKind kind);

// One servo axis on the card: the encoder instance, the SSERIAL channel of its 8I20 and the
// IO pins (IDROM pin numbers) its three Hall sensors are wired to.
struct AxisWiring {
  unsigned encoder = 0;
  unsigned sserial_port = 0;
  unsigned channel = 0;
  std::array<unsigned, 3> hall_pins{};
  bool operator==(const AxisWiring&) const = default;
};

struct BoardConfig {
  std::string card_name;  // space 7 and EEPROM: "7I96S"
  std::uint16_t lbp16_version = 3;
  std::uint16_t firmware_version = 17;
  std::uint16_t option_jumpers = 0;
  std::array<std::uint8_t, 6> mac{0x00, 0x60, 0x1B, 0x16, 0x00, 0x01};
  std::uint32_t eeprom_ip = 0xC0A80179;  // 192.168.1.121
  std::uint32_t eeprom_netmask = 0xFFFFFF00;
  std::uint8_t flash_id = 0x14;  // M25P16 electronic signature: 16 Mbit

  lbp::hm2::Idrom idrom;
  std::vector<lbp::hm2::ModuleDescriptor> modules;
  std::vector<lbp::hm2::PinDescriptor> pins;
  std::uint16_t idrom_address = lbp::hm2::kUsualIdromAddress;

  unsigned sserial_ports = 1;
  unsigned channels_per_port = 1;
  // The axes the configuration is laid out for (empty: no encoders).
  std::vector<AxisWiring> axes;

  static BoardConfig preset(BoardKind kind);
  static BoardConfig preset_7i92t_servo();
  // The module with this GTag, or nullptr.
  const lbp::hm2::ModuleDescriptor* find_module(std::uint8_t gtag) const;
  // The SSERIAL module descriptor (there is exactly one in the presets).
  const lbp::hm2::ModuleDescriptor& sserial_module() const;
};

}  // namespace i20::ethsim
