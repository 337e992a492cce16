// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/board_config.hpp"

#include <algorithm>
#include <cctype>

#include "error/error.hpp"

namespace i20::ethsim {

namespace hm2 = lbp::hm2;

namespace {

constexpr std::uint8_t kClockLow = 1;
constexpr std::uint8_t kOutput = 0x80;

hm2::Idrom base_idrom(const char* board_name, std::uint32_t io_ports, std::uint32_t port_width) {
  hm2::Idrom idrom;
  idrom.type = 3;
  idrom.offset_to_modules = 0x40;
  idrom.offset_to_pins = 0x40 + hm2::kMaxModules * hm2::ModuleDescriptor::kBytes;
  idrom.board_name = board_name;
  idrom.fpga_size = 20;
  idrom.fpga_pins = 256;
  idrom.io_ports = io_ports;
  idrom.io_width = io_ports * port_width;
  idrom.port_width = port_width;
  idrom.clock_low = 100'000'000;
  idrom.clock_high = 200'000'000;
  idrom.instance_stride0 = 0x04;
  idrom.instance_stride1 = 0x40;
  idrom.register_stride0 = 0x100;
  idrom.register_stride1 = 0x04;
  return idrom;
}

hm2::ModuleDescriptor module(std::uint8_t gtag, std::uint8_t version, std::uint8_t instances,
                             std::uint16_t base, std::uint8_t registers, std::uint8_t strides,
                             std::uint32_t multiple) {
  return hm2::ModuleDescriptor{.gtag = gtag,
                               .version = version,
                               .clock_tag = kClockLow,
                               .instances = instances,
                               .base_address = base,
                               .registers = registers,
                               .strides = strides,
                               .multiple_registers = multiple};
}

// SSERIAL: register stride 0 (0x100), instance stride 1 (0x40): the usual layout.
hm2::ModuleDescriptor sserial(std::uint8_t ports) {
  return module(hm2::gtag::kSserial, 0, ports, 0x5B00, hm2::sserial_reg::kCount, 0x10, 0x3C);
}

hm2::PinDescriptor gpio() {
  return hm2::PinDescriptor{};
}

hm2::PinDescriptor pin(std::uint8_t tag, std::uint8_t unit, std::uint8_t secondary_pin) {
  return hm2::PinDescriptor{.secondary_pin = secondary_pin,
                            .secondary_tag = tag,
                            .secondary_unit = unit,
                            .primary_tag = hm2::gtag::kIoPort};
}

// SSERIAL pins of one channel: RX in, TX out (pin numbers 1-based by channel).
void sserial_pins(std::vector<hm2::PinDescriptor>& pins, std::uint8_t port, unsigned channel, bool txen) {
  const auto n = static_cast<std::uint8_t>(channel + 1);
  pins.push_back(pin(hm2::gtag::kSserial, port, n));
  pins.push_back(pin(hm2::gtag::kSserial, port, static_cast<std::uint8_t>(kOutput | n)));
  if (txen) pins.push_back(pin(hm2::gtag::kSserial, port, static_cast<std::uint8_t>(kOutput | 0x10 | n)));
}

// The pin table of firmware 7i96s_d (LinuxCNC pncconf private_data.py): IO 0-10 the isolated
// inputs (InM 0), 11-16 the SSR/OUTM outputs, 17-26 five step/dir pairs, 27-29 encoder 0
// A/B/index, 30-32 the RS-422 SSERIAL channel (RX, TX, TXEN), 33 the spindle PWM, 34-50 the
// expansion connector P1. The SSR, OUTM and PWM modules are not simulated: their pins are
// plain GPIO here.
void encoder_pins(std::vector<hm2::PinDescriptor>& pins, std::uint8_t unit) {
  for (const std::uint8_t p : {hm2::encoder_pin::kA, hm2::encoder_pin::kB, hm2::encoder_pin::kIndex})
    pins.push_back(pin(hm2::gtag::kEncoder, unit, p));
}

BoardConfig preset_7i96s() {
  BoardConfig c;
  c.card_name = "7I96S";
  c.idrom = base_idrom("MESA7I96", 3, 17);
  c.modules = {module(hm2::gtag::kWatchdog, 0, 1, 0x0C00, 3, 0x00, 0),
               module(hm2::gtag::kIoPort, 0, 3, 0x1000, hm2::ioport_reg::kCount, 0x00, 0x1F),
               module(hm2::gtag::kEncoder, 2, 1, 0x3000, hm2::encoder_reg::kCount_, 0x00, 0x03),
               module(hm2::gtag::kStepGen, 2, 5, 0x2000, 10, 0x00, 0x1FF),
               sserial(1),
               module(hm2::gtag::kInm, 0, 1, 0x8500, hm2::inm_reg::kCount, 0x00, 0x1F),
               module(hm2::gtag::kLed, 0, 1, 0x0200, 1, 0x00, 0)};
  constexpr unsigned kIsolatedInputs = 11;
  for (unsigned input = 0; input < kIsolatedInputs; ++input)
    c.pins.push_back(pin(hm2::gtag::kInm, 0, static_cast<std::uint8_t>(input + 1)));
  while (c.pins.size() < 17) c.pins.push_back(gpio());
  for (std::uint8_t unit = 0; unit < 5; ++unit) {
    c.pins.push_back(pin(hm2::gtag::kStepGen, unit, kOutput | 1));
    c.pins.push_back(pin(hm2::gtag::kStepGen, unit, kOutput | 2));
  }
  encoder_pins(c.pins, 0);
  sserial_pins(c.pins, 0, 0, /*txen=*/true);
  while (c.pins.size() < c.idrom.io_width) c.pins.push_back(gpio());
  c.sserial_ports = 1;
  c.channels_per_port = 1;
  // The 8I20 on the RS-422 port, encoder 0, Halls on isolated inputs 0-2.
  c.axes = {AxisWiring{.encoder = 0, .sserial_port = 0, .channel = 0, .hall_pins = {0, 1, 2}}};
  return c;
}

BoardConfig preset_7i92t() {
  BoardConfig c;
  c.card_name = "7I92T";
  c.mac = {0x00, 0x60, 0x1B, 0x92, 0x00, 0x01};
  c.idrom = base_idrom("MESA7I92", 2, 17);
  c.modules = {module(hm2::gtag::kWatchdog, 0, 1, 0x0C00, 3, 0x00, 0),
               module(hm2::gtag::kIoPort, 0, 2, 0x1000, 5, 0x00, 0x1F), sserial(2),
               module(hm2::gtag::kLed, 0, 1, 0x0200, 1, 0x00, 0)};
  for (std::uint8_t port = 0; port < 2; ++port) {
    for (unsigned ch = 0; ch < 8; ++ch) sserial_pins(c.pins, port, ch, /*txen=*/false);
    c.pins.push_back(gpio());
  }
  c.sserial_ports = 2;
  c.channels_per_port = 8;
  return c;
}

// Per connector (17 pins) two axes: SSERIAL channels 0 and 1 of the connector's port (RX, TX
// each), two encoders (A, B, index each), two groups of three GPIO Hall inputs, one spare.
BoardConfig preset_7i92t_servo_config() {
  BoardConfig c = preset_7i92t();
  constexpr unsigned kAxesPerConnector = 2;
  constexpr unsigned kPortWidth = 17;
  c.modules = {module(hm2::gtag::kWatchdog, 0, 1, 0x0C00, 3, 0x00, 0),
               module(hm2::gtag::kIoPort, 0, 2, 0x1000, hm2::ioport_reg::kCount, 0x00, 0x1F),
               module(hm2::gtag::kEncoder, 2, 4, 0x3000, hm2::encoder_reg::kCount_, 0x00, 0x03), sserial(2),
               module(hm2::gtag::kLed, 0, 1, 0x0200, 1, 0x00, 0)};
  c.pins.clear();
  c.axes.clear();
  for (std::uint8_t port = 0; port < 2; ++port) {
    for (unsigned ch = 0; ch < kAxesPerConnector; ++ch) sserial_pins(c.pins, port, ch, /*txen=*/false);
    for (unsigned k = 0; k < kAxesPerConnector; ++k)
      encoder_pins(c.pins, static_cast<std::uint8_t>(port * kAxesPerConnector + k));
    for (unsigned k = 0; k < kAxesPerConnector; ++k) {
      const auto first = static_cast<unsigned>(c.pins.size());
      for (int i = 0; i < 3; ++i) c.pins.push_back(gpio());
      c.axes.push_back(AxisWiring{.encoder = port * kAxesPerConnector + k,
                                  .sserial_port = port,
                                  .channel = k,
                                  .hall_pins = {first, first + 1, first + 2}});
    }
    while (c.pins.size() < (port + 1u) * kPortWidth) c.pins.push_back(gpio());
  }
  c.sserial_ports = 2;
  c.channels_per_port = kAxesPerConnector;
  return c;
}

}  // namespace

BoardKind parse_board_kind(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char ch) { return std::tolower(ch); });
  if (lower == "7i96s") return BoardKind::I7i96s;
  if (lower == "7i92t") return BoardKind::I7i92t;
  throw UsageError("unknown card '" + std::string(text) + "': the virtual card can be 7i96s or 7i92t");
}

std::string_view board_kind_name(BoardKind kind) {
  return kind == BoardKind::I7i96s ? "7I96S" : "7I92T";
}

BoardConfig BoardConfig::preset(BoardKind kind) {
  return kind == BoardKind::I7i96s ? preset_7i96s() : preset_7i92t();
}

BoardConfig BoardConfig::preset_7i92t_servo() {
  return preset_7i92t_servo_config();
}

const hm2::ModuleDescriptor* BoardConfig::find_module(std::uint8_t gtag) const {
  const auto it = std::find_if(modules.begin(), modules.end(), [&](const auto& m) { return m.gtag == gtag; });
  return it == modules.end() ? nullptr : &*it;
}

const hm2::ModuleDescriptor& BoardConfig::sserial_module() const {
  const auto it =
      std::find_if(modules.begin(), modules.end(), [](const auto& m) { return hm2::is_sserial(m.gtag); });
  if (it == modules.end()) throw UsageError("card configuration without an SSERIAL module");
  return *it;
}

}  // namespace i20::ethsim
