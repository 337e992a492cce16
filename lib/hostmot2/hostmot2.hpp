// SPDX-License-Identifier: GPL-2.0-or-later
// HostMot2 identification and the SSERIAL/SSLBP register interface (docs/facts.md section 5,
// 8I20 manual "SSLBP"). Pure data: parse what a card's registers hold, compute where
// the SSERIAL registers live, encode the SSLBP command words. No I/O.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lbp/bytes.hpp"

namespace i20::lbp::hm2 {

// ---- Identification area (space 0) -----------------------------------------------------

inline constexpr std::uint16_t kCookieAddress = 0x0100;
inline constexpr std::uint16_t kConfigNameAddress = 0x0104;  // "HOSTMOT2", 8 characters
inline constexpr std::uint16_t kIdromPointerAddress = 0x010C;
inline constexpr std::uint32_t kCookie = 0x55AACAFE;
inline constexpr char kConfigName[] = "HOSTMOT2";
inline constexpr std::uint16_t kUsualIdromAddress = 0x0400;

// The 16 bytes at 0x0100: cookie, config name, IDROM pointer.
struct IdentArea {
  std::uint32_t cookie = 0;
  std::string config_name{};
  std::uint32_t idrom_address = 0;

  bool valid() const { return cookie == kCookie; }
  static IdentArea parse(ByteView bytes);  // 16 bytes
  Bytes encode() const;
};

// ---- IDROM ---------------------------------------------------------------------------

struct Idrom {
  std::uint32_t type = 3;
  std::uint32_t offset_to_modules = 0x40;  // from the IDROM start
  std::uint32_t offset_to_pins = 0x1C0;
  std::string board_name{};  // 8 characters, e.g. "MESA7I96"
  std::uint32_t fpga_size = 0;
  std::uint32_t fpga_pins = 0;
  std::uint32_t io_ports = 0;
  std::uint32_t io_width = 0;
  std::uint32_t port_width = 0;
  std::uint32_t clock_low = 0;
  std::uint32_t clock_high = 0;
  std::uint32_t instance_stride0 = 0;
  std::uint32_t instance_stride1 = 0;
  std::uint32_t register_stride0 = 0;
  std::uint32_t register_stride1 = 0;

  static constexpr std::size_t kBytes = 64;  // 16 words
  static Idrom parse(ByteView bytes);        // exactly kBytes
  Bytes encode() const;
};

// Module GTags (HostMot2 register map).
namespace gtag {
inline constexpr std::uint8_t kNone = 0x00;
inline constexpr std::uint8_t kWatchdog = 0x02;
inline constexpr std::uint8_t kIoPort = 0x03;
inline constexpr std::uint8_t kEncoder = 0x04;
inline constexpr std::uint8_t kStepGen = 0x05;
inline constexpr std::uint8_t kPwmGen = 0x06;
inline constexpr std::uint8_t kInm = 0x23;  // 35: debounced input module (7I96S isolated inputs)
inline constexpr std::uint8_t kLed = 0x80;
inline constexpr std::uint8_t kSserial = 0xC1;
inline constexpr std::uint8_t kSserialB = 0xC6;  // newer SSERIAL, same register interface
}  // namespace gtag

bool is_sserial(std::uint8_t tag);

// 12-byte module descriptor.
struct ModuleDescriptor {
  std::uint8_t gtag = 0;
  std::uint8_t version = 0;
  std::uint8_t clock_tag = 0;
  std::uint8_t instances = 0;
  std::uint16_t base_address = 0;
  std::uint8_t registers = 0;
  std::uint8_t strides = 0;  // low nibble register stride select, high nibble instance stride select
  std::uint32_t multiple_registers = 0;

  static constexpr std::size_t kBytes = 12;
  static ModuleDescriptor parse(ByteView bytes);
  Bytes encode() const;

  std::uint32_t register_stride(const Idrom& idrom) const;
  std::uint32_t instance_stride(const Idrom& idrom) const;
  // Address of register `reg` (0-based) of instance `instance`. Throws UsageError when the
  // instance or register does not exist or the address leaves the 64K space.
  std::uint16_t register_address(const Idrom& idrom, unsigned reg, unsigned instance) const;
  // The register and instance at `address`, the inverse of register_address(): nullopt when
  // the address is none of this module's registers. A register whose bit in
  // multiple_registers is clear exists once (instance 0).
  struct Slot {
    unsigned reg = 0;
    unsigned instance = 0;
    bool operator==(const Slot&) const = default;
  };
  std::optional<Slot> slot_at(const Idrom& idrom, std::uint16_t address) const;

  bool operator==(const ModuleDescriptor&) const = default;
};

// Module list at IDROM + OffsetToModules; it ends at the first GTag 0 (or at `max`).
inline constexpr std::size_t kMaxModules = 32;
std::vector<ModuleDescriptor> parse_modules(ByteView bytes);

// 4-byte pin descriptor.
struct PinDescriptor {
  std::uint8_t secondary_pin = 0;  // bit 7 set: output
  std::uint8_t secondary_tag = 0;  // module owning the pin when it is not GPIO (0: none)
  std::uint8_t secondary_unit = 0;
  std::uint8_t primary_tag = gtag::kIoPort;

  static constexpr std::size_t kBytes = 4;
  static PinDescriptor parse(ByteView bytes);
  Bytes encode() const;
  bool operator==(const PinDescriptor&) const = default;
};
inline constexpr std::size_t kMaxPins = 144;
std::vector<PinDescriptor> parse_pins(ByteView bytes, std::size_t count);

// ---- Encoder, IOPort and InM registers (LinuxCNC hm2/encoder.c, ioport.c, inm.c; FW regmap) ----

// Register numbers within the quadrature counter module (multiplied by the register stride).
namespace encoder_reg {
inline constexpr unsigned kCount = 0;             // count (0-15), timestamp of the last count change (16-31)
inline constexpr unsigned kLatchControl = 1;      // latched count (16-31), control and status (0-15)
inline constexpr unsigned kTimestampDivider = 2;  // TSDiv: TSCount runs at ClockLow / (TSDiv + 2)
inline constexpr unsigned kTimestampCount = 3;    // TSCount, 16-bit, read only
inline constexpr unsigned kFilterRate = 4;        // QFilterRate
inline constexpr unsigned kCount_ = 5;
}  // namespace encoder_reg

// Latch/control register bits.
namespace encoder_bit {
inline constexpr std::uint32_t kInputA = 1u << 0;  // read only, live
inline constexpr std::uint32_t kInputB = 1u << 1;
inline constexpr std::uint32_t kInputIndex = 1u << 2;
inline constexpr std::uint32_t kIndexPolarity = 1u << 3;  // 1: the rising edge is the index event
inline constexpr std::uint32_t kLatchOnIndex = 1u << 4;
inline constexpr std::uint32_t kClearOnIndex = 1u << 5;
inline constexpr std::uint32_t kJustOnce = 1u << 6;
inline constexpr std::uint32_t kAbGateIndex = 1u << 7;
inline constexpr std::uint32_t kIndexMaskPolarity = 1u << 8;
inline constexpr std::uint32_t kIndexMask = 1u << 9;
inline constexpr std::uint32_t kCounterMode = 1u << 10;  // 1: up/down (A = count, B = direction)
inline constexpr std::uint32_t kFilter = 1u << 11;
inline constexpr std::uint32_t kProbePolarity = 1u << 12;
inline constexpr std::uint32_t kLatchOnProbe = 1u << 13;
inline constexpr std::uint32_t kAbMaskPolarity = 1u << 14;
inline constexpr std::uint32_t kQuadError = 1u << 15;
}  // namespace encoder_bit

// Secondary pin numbers of an encoder's pins in the pin descriptors.
namespace encoder_pin {
inline constexpr std::uint8_t kA = 1;
inline constexpr std::uint8_t kB = 2;
inline constexpr std::uint8_t kIndex = 3;
}  // namespace encoder_pin

namespace ioport_reg {
inline constexpr unsigned kData = 0;       // read: pin levels; write: output values
inline constexpr unsigned kDirection = 1;  // DDR, 1 = output
inline constexpr unsigned kAltSource = 2;  // 1 = the pin's module drives it
inline constexpr unsigned kOpenDrain = 3;
inline constexpr unsigned kOutputInvert = 4;
inline constexpr unsigned kCount = 5;
}  // namespace ioport_reg

namespace inm_reg {
inline constexpr unsigned kControl = 0;  // bits 0-4 read only: last input number; bit 5 global invert
inline constexpr unsigned kFilter = 1;   // 1 per input: the long filter time
inline constexpr unsigned kFilteredData = 2;
inline constexpr unsigned kRawData = 3;
inline constexpr unsigned kMpg = 4;
inline constexpr unsigned kCount = 5;
inline constexpr std::uint32_t kGlobalInvert = 1u << 5;
inline constexpr std::uint32_t kMaxBitMask = 0x1F;
}  // namespace inm_reg

// ---- SSERIAL registers ------------------------------------------------------------------

// Register numbers within the SSERIAL module (multiplied by the register stride).
namespace sserial_reg {
inline constexpr unsigned kCommand = 0;
inline constexpr unsigned kData = 1;
inline constexpr unsigned kCs = 2;
inline constexpr unsigned kInterface0 = 3;
inline constexpr unsigned kInterface1 = 4;
inline constexpr unsigned kInterface2 = 5;
inline constexpr unsigned kCount = 6;
}  // namespace sserial_reg

// Per-channel registers sit 4 bytes apart inside the instance's register.
inline constexpr unsigned kChannelStride = 4;
inline constexpr unsigned kMaxChannelsPerPort = 8;

// Where one SSERIAL instance ("port") keeps its registers.
struct SserialRegisters {
  std::uint16_t command = 0;
  std::uint16_t data = 0;
  std::uint16_t cs0 = 0;  // channel 0; channel n at + 4 n
  std::uint16_t interface0_0 = 0;
  std::uint16_t interface1_0 = 0;
  std::uint16_t interface2_0 = 0;

  std::uint16_t cs(unsigned channel) const {
    return static_cast<std::uint16_t>(cs0 + kChannelStride * channel);
  }
  std::uint16_t interface0(unsigned channel) const {
    return static_cast<std::uint16_t>(interface0_0 + kChannelStride * channel);
  }
  std::uint16_t interface1(unsigned channel) const {
    return static_cast<std::uint16_t>(interface1_0 + kChannelStride * channel);
  }
  std::uint16_t interface2(unsigned channel) const {
    return static_cast<std::uint16_t>(interface2_0 + kChannelStride * channel);
  }

  // From the IDROM strides and the module descriptor. Throws UsageError if the module is
  // not SSERIAL or has no such instance.
  static SserialRegisters locate(const Idrom& idrom, const ModuleDescriptor& module, unsigned instance);
  bool operator==(const SserialRegisters&) const = default;
};

// ---- SSLBP command words and local parameters ---------------------------------------------

namespace sslbp {

inline constexpr std::uint32_t kWrite = 0x8000;
inline constexpr std::uint32_t kReset = 0x4000;
inline constexpr std::uint32_t kRequest = 0x2000;
inline constexpr std::uint32_t kDoit = 0x1000;
inline constexpr std::uint32_t kStart = 0x0800;
inline constexpr std::uint32_t kStop = 0x0800;  // start/stop bit with type 000
inline constexpr std::uint32_t kStartNormal = 0x0900;
inline constexpr std::uint32_t kStartSetup = 0x0F00;
inline constexpr std::uint32_t kTypeMask = 0x0700;
inline constexpr std::uint32_t kChannelMask = 0x00FF;
inline constexpr std::uint32_t kLocalAddressMask = 0x03FF;

inline std::uint32_t stop(std::uint8_t mask = 0) {
  return kStop | mask;
}  // mask 0: stop all
inline std::uint32_t start_normal(std::uint8_t mask) {
  return kStartNormal | mask;
}
inline std::uint32_t start_setup(std::uint8_t mask) {
  return kStartSetup | mask;
}
inline std::uint32_t doit(std::uint8_t mask) {
  return kDoit | mask;
}
inline std::uint32_t read_local(std::uint16_t address) {
  return kRequest | (address & kLocalAddressMask);
}
inline std::uint32_t write_local(std::uint16_t address) {
  return kWrite | kRequest | (address & kLocalAddressMask);
}

// Local SSLBP parameters (one byte each unless noted).
namespace param {
inline constexpr std::uint16_t kInterfaceType = 0;
inline constexpr std::uint16_t kWidth = 1;
inline constexpr std::uint16_t kMajorVersion = 2;
inline constexpr std::uint16_t kMinorVersion = 3;
inline constexpr std::uint16_t kChannelStart = 4;
inline constexpr std::uint16_t kChannelStride = 5;
inline constexpr std::uint16_t kProcessorType = 6;
inline constexpr std::uint16_t kChannels = 7;
inline constexpr std::uint16_t kClock = 0x230;  // 32 bit, little endian
// Per-channel baud rate (32 bit) at channel start + channel * stride + this offset.
inline constexpr std::uint16_t kBaudRateOffset = 42;
}  // namespace param

// What the channel's CS register says when read (8I20 manual, "CS REGISTER").
struct ChannelStatus {
  std::uint32_t raw = 0;
  std::uint8_t remote_mode() const { return static_cast<std::uint8_t>(raw >> 24); }  // 0x80: 8I20
  std::uint8_t state() const { return static_cast<std::uint8_t>(raw >> 16); }
  std::uint8_t status() const { return static_cast<std::uint8_t>(raw >> 8); }
  std::uint8_t errors() const { return static_cast<std::uint8_t>(raw); }  // sticky until stop
  bool ok() const { return status() == 0 && errors() == 0; }
  bool timed_out() const { return (errors() & kTimeoutError) != 0; }
  bool crc_error() const { return (errors() & kCrcError) != 0; }
  // The channel is not communicating (stopped, e.g. by a reset of the card): a DOIT cannot
  // run on it until it is started again.
  bool not_ready() const { return (status() & kNotReady) != 0; }
  // "communication not ready, timeout" or "ok".
  std::string describe() const;

  // Status byte (byte 1).
  static constexpr std::uint8_t kNotReady = 0x80;
  static constexpr std::uint8_t kNoRemoteId = 0x40;
  static constexpr std::uint8_t kCommunicationError = 0x20;
  static constexpr std::uint8_t kRemoteFault = 0x01;
  // Error byte (byte 0).
  static constexpr std::uint8_t kTooManyErrors = 0x80;
  static constexpr std::uint8_t kExtraCharacter = 0x10;
  static constexpr std::uint8_t kTimeoutError = 0x08;
  static constexpr std::uint8_t kOverrun = 0x04;
  static constexpr std::uint8_t kInvalidCookie = 0x02;
  static constexpr std::uint8_t kCrcError = 0x01;
};

inline constexpr std::uint8_t kRemoteMode8i20 = 0x80;
// "8I20" read as a little-endian word from INTERFACE1 after a setup start.
inline constexpr std::uint32_t kName8i20 = 0x30324938;

// Setup-mode passthrough: CS = LBP header << 24 | address (data commands) or
// local command << 24 (local reads/writes); INTERFACE0 carries write data and read results.
inline std::uint32_t passthrough_cs(std::uint8_t header, std::uint16_t address = 0) {
  return (std::uint32_t{header} << 24) | address;
}

// Four characters of a little-endian word ("8I20" from 0x30324938), NULs dropped.
std::string name_of_word(std::uint32_t word);

}  // namespace sslbp

}  // namespace i20::lbp::hm2
