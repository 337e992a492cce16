// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual Ethernet card: LBP16 request packets in, reply packets out, like a 7I96S
// or 7I92T (manuals, "LBP16", "SUPPORTED MEMORY SPACES"). Pure logic driven by the time
// you give it; BoardServer adds the UDP socket.
//
// Spaces and their rules:
//   0 HostMot2 registers, 32-bit: cookie, "HOSTMOT2", IDROM pointer, IDROM, modules,
//     pins (read only), the SSERIAL ports (SslbpEngine), the encoders, GPIO ports and InM
//     inputs (FeedbackBank), everything else plain registers.
//   1 Ethernet chip (KSZ8851), 16-bit: CIDER reads 0x8872.
//   2 Ethernet EEPROM, 16-bit: MAC, card name, IP, netmask. The first 0x20 bytes are read
//     only; writes need EEPROMWEna = 0x5A02 earlier in the same packet.
//   3 FPGA flash, 32-bit: FL_ADDR, FL_DATA (auto-increments by 4), FL_ID, SEC_ERASE;
//     writes and erases need EEPROMWEna = 0x5A03.
//   4 timers, 16-bit: uSTimeStamp, WaituS (delays the rest of the packet), scratch.
//   6 LBP16 status/control, 16-bit: errors, counters, Scratch, EEPROMWEna (cleared at
//     the end of every packet).
//   7 read-only card information, 16-bit: name, LBP16 and firmware versions.
// Each has its info area (cookie 0x5A0N, MemSizes, MemRanges, address pointer, name).
//
// Choices where the manuals are silent:
// - An access with an element size the space does not allow, to space 5, or outside a
//   space sets LBPMemError; reads return zeros so the reply keeps the size the host
//   computed. A refused write (read-only, no EEPROMWEna) sets LBPWriteError.
// - A packet that ends inside a command or holds a count of 0 sets LBPParseError; the
//   commands before it are executed and their data returned.
// - A packet without read data gets no reply at all.
// - LBPReset, FPGAICAP, LEDMode and the WaitForHM2 timers are plain registers: the
//   simulated card neither reboots nor waits for HostMot2 timers.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "ethsim/board_config.hpp"
#include "ethsim/feedback_bank.hpp"
#include "ethsim/remote_device.hpp"
#include "ethsim/sslbp_engine.hpp"
#include "lbp16/lbp16.hpp"

namespace i20::ethsim {

// Builds the device on one channel; nullptr leaves the channel empty.
using RemoteFactory = std::function<std::unique_ptr<RemoteLbpDevice>(unsigned port, unsigned channel)>;

struct VirtualBoardOptions {
  BoardConfig config = BoardConfig::preset(BoardKind::I7i96s);
  SslbpConfig sslbp{};  // `channels` is taken from the card configuration
  RemoteFactory remotes{};
};

struct BoardStats {
  std::uint64_t packets = 0;
  std::uint64_t replies = 0;
  std::uint64_t parse_errors = 0;
  std::uint64_t mem_errors = 0;
  std::uint64_t write_errors = 0;
};

// Space 6 layout.
namespace status_reg {
inline constexpr std::uint16_t kErrors = 0x00;
inline constexpr std::uint16_t kParseErrors = 0x02;
inline constexpr std::uint16_t kMemErrors = 0x04;
inline constexpr std::uint16_t kWriteErrors = 0x06;
inline constexpr std::uint16_t kRxPackets = 0x08;
inline constexpr std::uint16_t kRxUdp = 0x0A;
inline constexpr std::uint16_t kRxBad = 0x0C;
inline constexpr std::uint16_t kTxPackets = 0x0E;
inline constexpr std::uint16_t kTxUdp = 0x10;
inline constexpr std::uint16_t kTxBad = 0x12;
inline constexpr std::uint16_t kScratch = 0x18;
inline constexpr std::uint16_t kEepromWriteEnable = 0x1A;
inline constexpr std::uint16_t kLbpReset = 0x1C;
// ErrorReg bits.
inline constexpr std::uint16_t kParseErrorBit = 0x01;
inline constexpr std::uint16_t kMemErrorBit = 0x02;
inline constexpr std::uint16_t kWriteErrorBit = 0x04;
}  // namespace status_reg

class VirtualBoard {
 public:
  explicit VirtualBoard(VirtualBoardOptions options = {}, Clock::time_point now = Clock::now());

  // Executes one request packet received at `now`. Returns the reply, or nullopt when the
  // packet holds no reads (the card sends nothing).
  std::optional<lbp::Bytes> handle(lbp::ByteView request, Clock::time_point now);
  // Time passes without packets: SSLBP completes commands, chatters, remotes tick.
  void advance(Clock::time_point now);
  // The card's own clock: later than real time after a WaituS; the reply leaves then.
  Clock::time_point board_time() const { return now_; }

  SslbpEngine& sslbp(unsigned port) { return *ports_.at(port); }
  unsigned sserial_ports() const { return static_cast<unsigned>(ports_.size()); }
  const BoardConfig& config() const { return config_; }
  const BoardStats& stats() const { return stats_; }
  std::uint16_t status_register(std::uint16_t address) const;
  std::uint16_t eeprom_word(std::uint16_t address) const;
  // The value last written to a space 0 register (or the IDROM's content there).
  std::uint32_t hm2_register(std::uint16_t address) const { return hm2_.at(address / 4); }
  // Encoders, GPIO and InM inputs: connect shafts and inject faults here.
  FeedbackBank& feedback() { return feedback_; }
  // Where SSERIAL port `port` keeps its registers in space 0.
  lbp::hm2::SserialRegisters sserial_registers(unsigned port) const {
    return lbp::hm2::SserialRegisters::locate(config_.idrom, config_.sserial_module(), port);
  }

 private:
  void execute(const lbp::lbp16::Command& command, lbp::Bytes& reply);
  std::uint64_t read_element(std::uint8_t space, std::uint16_t address, lbp::lbp16::Width width, bool info);
  void write_element(std::uint8_t space, std::uint16_t address, lbp::lbp16::Width width, std::uint64_t value);
  bool width_allowed(std::uint8_t space, lbp::lbp16::Width width, bool info) const;
  lbp::lbp16::InfoArea info_area(std::uint8_t space) const;

  std::uint32_t hm2_read(std::uint16_t address);
  void hm2_write(std::uint16_t address, std::uint32_t value);
  // SSERIAL register behind a space 0 address, if any: {port, register, channel}.
  struct SserialTarget {
    unsigned port, reg, channel;
  };
  std::optional<SserialTarget> sserial_at(std::uint16_t address) const;
  bool hm2_read_only(std::uint16_t address) const;
  std::uint32_t flash_read(std::uint16_t address);
  void flash_write(std::uint16_t address, std::uint32_t value);

  void mem_error();
  void write_error();

  BoardConfig config_;
  std::vector<std::unique_ptr<SslbpEngine>> ports_;
  FeedbackBank feedback_;
  std::vector<std::uint32_t> hm2_ = std::vector<std::uint32_t>(0x4000, 0);
  std::vector<std::uint16_t> eth_chip_ = std::vector<std::uint16_t>(0x80, 0);
  std::vector<std::uint16_t> eeprom_ = std::vector<std::uint16_t>(0x40, 0);
  std::vector<std::uint16_t> timers_ = std::vector<std::uint16_t>(0x10, 0);
  std::vector<std::uint16_t> status_ = std::vector<std::uint16_t>(0x10, 0);
  std::vector<std::uint16_t> info_ = std::vector<std::uint16_t>(0x10, 0);  // space 7
  std::map<std::uint32_t, std::uint32_t> flash_;  // written words; everything else reads erased
  std::uint32_t flash_address_ = 0;
  std::array<std::uint16_t, lbp::lbp16::kSpaceCount> pointer_{};
  std::array<std::uint16_t, lbp::lbp16::kSpaceCount> info_pointer_{};
  std::uint16_t idrom_end_ = 0;
  Clock::time_point start_;
  Clock::time_point now_;
  BoardStats stats_;
};

}  // namespace i20::ethsim
