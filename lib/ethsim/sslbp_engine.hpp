// SPDX-License-Identifier: GPL-2.0-or-later
// The SSLBP processor of one virtual SSERIAL port (8I20 manual, "SSLBP"): COMMAND and
// DATA, local parameters, per-channel CS/INTERFACE0..2, stop / normal start / setup
// start / DOIT / local read and write, in front of the remote devices on its channels.
//
// Model (where the manual is silent, the choice is written here):
// - Commands take time: COMMAND reads back non-zero until the operation's serial traffic
//   (at the port's baud) plus `processing` per step has passed. Results appear in the
//   registers only then. A COMMAND write while busy is ignored and counted.
// - Bit 14 (reset) holds the processor in reset: every channel stops, COMMAND reads
//   back the written value until a write without bit 14.
// - The interface registers are shared memory: the host's writes read back until the
//   processor overwrites them (CS with the channel status, INTERFACE0/1 with results).
// - Setup start: the card name comes from local reads 0xD0..0xD3, the unit number from
//   a 4-byte read of UNITNUMBER (address 2344). Normal start adds the device's own setup
//   (RemoteLbpDevice::normal_start_commands) and then "chatters" (cookie reads every
//   10 ms) until the first DOIT.
// - DOIT in setup mode runs the passthrough: CS holds the LBP header and address
//   (data commands) or the local command, INTERFACE0 the write data; a read's answer
//   lands right justified in INTERFACE0. In normal mode DOIT runs the 8I20's cycle RPC
//   and presents bus voltage (10 mV) and temperature in whole degrees C in INTERFACE0,
//   FAULT and STATUS in INTERFACE1 (8I20 manual, 8I20 SPECIFIC INTERFACE REGISTER 0/1).
// - A failed transfer sets the channel's DATA bit and sticky CS error bits (timeout,
//   CRC, extra character); only a stop clears the error byte.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "ethsim/remote_device.hpp"
#include "hostmot2/hostmot2.hpp"

namespace i20::ethsim {

struct SslbpConfig {
  unsigned channels = 1;
  std::uint8_t version_major = 0;  // simulation values: the firmware's real numbers are not published
  std::uint8_t version_minor = 40;
  std::uint8_t interface_type = 0x12;
  std::uint8_t processor_type = 0xD8;
  std::uint32_t clock_hz = 100'000'000;
  std::uint32_t baud = 2'500'000;                                  // towards the remotes
  Clock::duration processing = std::chrono::microseconds(20);      // per command and per remote step
  Clock::duration remote_timeout = std::chrono::milliseconds(20);  // covers an 8I20 EEPROM write
  Clock::duration chatter_period = std::chrono::milliseconds(10);
};

// Local parameter layout of the virtual SSLBP.
inline constexpr std::uint8_t kSimChannelStart = 0x40;
inline constexpr std::uint8_t kSimChannelStride = 0x40;

enum class ChannelMode { Stopped, Setup, Normal };

struct SslbpStats {
  std::uint64_t commands = 0;
  std::uint64_t ignored_while_busy = 0;
  std::uint64_t doits = 0;
  std::uint64_t remote_exchanges = 0;
  std::uint64_t remote_failures = 0;
  std::uint64_t chatter = 0;
};

class SslbpEngine {
 public:
  // `remotes[ch]` may be null (nothing connected). Size must be config.channels.
  SslbpEngine(SslbpConfig config, std::vector<std::unique_ptr<RemoteLbpDevice>> remotes,
              Clock::time_point now);

  // Register access by SSERIAL register number (lbp::hm2::sserial_reg) and channel.
  std::uint32_t read(unsigned reg, unsigned channel, Clock::time_point now);
  void write(unsigned reg, unsigned channel, std::uint32_t value, Clock::time_point now);
  // Completes due operations, chatters, lets remotes' time run.
  void advance(Clock::time_point now);

  bool busy() const { return pending_.has_value(); }
  bool held_in_reset() const { return in_reset_; }
  // The card reset or came back from a power loss: every channel stopped, nothing pending,
  // the processor running again (a host must start its channels anew).
  void power_on_reset(Clock::time_point now);
  ChannelMode mode(unsigned channel) const { return channels_.at(channel).mode; }
  RemoteLbpDevice* remote(unsigned channel) { return channels_.at(channel).remote.get(); }
  const SslbpStats& stats() const { return stats_; }
  const SslbpConfig& config() const { return config_; }
  std::uint8_t local(std::uint16_t address) const {
    return local_[address & lbp::hm2::sslbp::kLocalAddressMask];
  }

 private:
  // CS and INTERFACE0..2 as one side sees them. The host's writes and the processor's
  // results are separate latches: in normal mode the host writes QSETPOINT/ANGLE to
  // INTERFACE0 and reads bus voltage/temperature from it (manual, NORMAL MODE OPERATION).
  struct Registers {
    std::uint32_t cs = 0, interface0 = 0, interface1 = 0, interface2 = 0;
  };
  struct Channel {
    std::unique_ptr<RemoteLbpDevice> remote;
    ChannelMode mode = ChannelMode::Stopped;
    Registers host;           // written by the host, read by the processor
    Registers card;           // written by the processor when an operation completes, read by the host
    std::uint8_t errors = 0;  // CS byte 0, sticky until stop
    std::uint8_t remote_mode = 0;
    bool doit_seen = false;
    Clock::time_point last_traffic{};
  };
  // What becomes visible when the running operation completes.
  struct Pending {
    std::uint32_t command = 0;
    Clock::time_point done{};
    std::optional<std::uint8_t> data{};
    std::vector<std::optional<Registers>> results{};  // per channel
  };

  // One LBP exchange with a channel's remote; nullopt (and sticky error bits) on failure.
  std::optional<lbp::Bytes> transfer(Channel& ch, const lbp::Bytes& command, std::size_t reply_bytes,
                                     Clock::time_point& t);
  void execute(std::uint32_t command, Clock::time_point now);
  void stop(std::uint8_t mask, Pending& p);
  bool start(Channel& ch, ChannelMode mode, Registers& out, Clock::time_point& t);
  bool doit(Channel& ch, Registers& out, Clock::time_point& t);
  bool passthrough(Channel& ch, Registers& out, Clock::time_point& t);
  std::uint32_t status_word(const Channel& ch, std::uint8_t status) const;
  void chatter(Channel& ch, Clock::time_point now);
  void complete();

  SslbpConfig config_;
  std::vector<Channel> channels_;
  std::array<std::uint8_t, 1024> local_{};
  std::uint32_t reset_command_ = 0;  // while bit 14 holds the processor in reset
  std::uint32_t data_ = 0;
  bool in_reset_ = false;
  std::optional<Pending> pending_;
  Clock::time_point now_;
  SslbpStats stats_;
};

}  // namespace i20::ethsim
