// SPDX-License-Identifier: GPL-2.0-or-later
// What an Ethernet Anything-I/O card is and what it carries: space 7 identification,
// the HostMot2 IDROM with its modules and pins, and the SSERIAL ports among them.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "eth/transport.hpp"
#include "hostmot2/hostmot2.hpp"

namespace i20::eth {

struct BoardIdentity {
  std::string card_name{};  // "7I96S"
  std::uint16_t lbp16_version = 0;
  std::uint16_t firmware_version = 0;

  // The LBP16 timer/utility area (space 4, WaituS) exists from LBP16 version 3 on (the
  // version mesaflash checks before it reads the timers).
  bool has_timer_space() const { return lbp16_version >= 3; }
};

// Reads space 7. One round trip.
BoardIdentity identify(Lbp16Transport& bus);

// One SSERIAL instance ("port").
struct SserialPort {
  unsigned index = 0;
  std::uint8_t gtag = lbp::hm2::gtag::kSserial;
  std::uint8_t version = 0;
  lbp::hm2::SserialRegisters registers{};
};

struct HostMot2Info {
  lbp::hm2::IdentArea ident{};
  lbp::hm2::Idrom idrom{};
  std::vector<lbp::hm2::ModuleDescriptor> modules{};
  std::vector<lbp::hm2::PinDescriptor> pins{};

  const lbp::hm2::ModuleDescriptor* find(std::uint8_t gtag) const;
  // Every instance of every SSERIAL module (GTag 0xC1 or 0xC6), numbered from 0 in
  // module order.
  std::vector<SserialPort> sserial_ports() const;
};

// Checks the cookie 0x55AACAFE at 0x100 and reads IDROM, modules and pins. Three round
// trips. Throws DiscoveryError when the card does not hold a HostMot2 configuration.
HostMot2Info read_hostmot2(Lbp16Transport& bus);

// The SSERIAL port `index`, or DiscoveryError naming what the card has.
SserialPort find_sserial_port(const HostMot2Info& info, unsigned index);

}  // namespace i20::eth
