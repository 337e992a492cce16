// SPDX-License-Identifier: GPL-2.0-or-later
// Encoders and Hall inputs read through the virtual card's LBP16 interface, at the
// addresses its IDROM declares, the way LinuxCNC's hostmot2 reads them each servo period.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "error/error.hpp"
#include "ethsim/virtual_board.hpp"
#include "hostmot2/hostmot2.hpp"
#include "lbp16/lbp16.hpp"

using namespace i20;
using namespace i20::ethsim;
using namespace std::chrono_literals;
namespace hm2 = i20::lbp::hm2;
namespace lbp16 = i20::lbp::lbp16;

namespace {

constexpr std::uint32_t kArmIndex = hm2::encoder_bit::kLatchOnIndex | hm2::encoder_bit::kJustOnce;

// A host that knows the card only by what its IDROM says, like hostmot2.
class Host {
 public:
  Host(VirtualBoard& board, Clock::time_point t0) : card_(board), t0_(t0) {
    const auto ident = hm2::IdentArea::parse(read_bytes(hm2::kCookieAddress, 4));
    idrom_address_ = static_cast<std::uint16_t>(ident.idrom_address);
    idrom = hm2::Idrom::parse(read_bytes(idrom_address_, 16));
    modules = hm2::parse_modules(read_bytes(
        static_cast<std::uint16_t>(idrom_address_ + idrom.offset_to_modules), hm2::kMaxModules * 3));
    pins = hm2::parse_pins(
        read_bytes(static_cast<std::uint16_t>(idrom_address_ + idrom.offset_to_pins), idrom.io_width),
        idrom.io_width);
  }

  const hm2::ModuleDescriptor& module(std::uint8_t gtag) const {
    for (const auto& m : modules)
      if (m.gtag == gtag) return m;
    throw std::runtime_error("no module with that GTag");
  }
  std::uint16_t address(std::uint8_t gtag, unsigned reg, unsigned instance = 0) const {
    return module(gtag).register_address(idrom, reg, instance);
  }

  void at(Clock::duration t) { now_ = t0_ + t; }
  std::vector<std::uint32_t> read(const std::vector<std::uint16_t>& addresses) {
    std::vector<lbp16::Command> commands;
    for (const auto a : addresses) commands.push_back(lbp16::read_hm2(a));
    const auto reply = card_.handle(lbp16::encode_packet(commands), now_);
    std::vector<std::uint32_t> out;
    for (const auto& part : lbp16::split_reply(commands, reply.value_or(lbp::Bytes{})))
      out.push_back(static_cast<std::uint32_t>(lbp::read_le(part)));
    return out;
  }
  std::uint32_t read(std::uint16_t address) { return read(std::vector<std::uint16_t>{address})[0]; }
  void write(std::uint16_t address, std::uint32_t value) {
    const std::vector<lbp16::Command> commands{lbp16::write_hm2(address, value)};
    card_.handle(lbp16::encode_packet(commands), now_);
  }

  hm2::Idrom idrom;
  std::vector<hm2::ModuleDescriptor> modules;
  std::vector<hm2::PinDescriptor> pins;

 private:
  lbp::Bytes read_bytes(std::uint16_t address, unsigned words) {
    const std::vector<lbp16::Command> commands{lbp16::read_hm2(address, words)};
    return lbp16::split_reply(commands, card_.handle(lbp16::encode_packet(commands), now_).value())[0];
  }

  VirtualBoard& card_;
  Clock::time_point t0_;
  Clock::time_point now_ = t0_;
  std::uint16_t idrom_address_ = 0;
};

double seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// InM/GPIO bits of three Hall inputs (H1 in the lowest bit) from HallSensors' H1H2H3 code.
unsigned input_bits(unsigned code) {
  return (code >> 2 & 1u) | (code >> 1 & 1u) << 1 | (code & 1u) << 2;
}

class FeedbackBoard : public ::testing::Test {
 protected:
  Clock::time_point t0 = Clock::time_point{} + 1h;
  // 5 rev/s from t0: 10 counts per ms with a 2000-count encoder.
  ShaftSource turning = [t0 = t0](Clock::time_point t) { return 5.0 * seconds(t - t0); };
};

}  // namespace

TEST_F(FeedbackBoard, The7i96sIdromHasTheFeedbackHostmot2NeedsWhere7i96sDPutsIt) {
  VirtualBoard board(VirtualBoardOptions{}, t0);
  Host host(board, t0);
  EXPECT_EQ(host.module(hm2::gtag::kEncoder).instances, 1);
  EXPECT_EQ(host.module(hm2::gtag::kInm).instances, 1);
  EXPECT_EQ(host.module(hm2::gtag::kIoPort).instances, 3);
  for (unsigned pin = 0; pin <= 10; ++pin) {
    EXPECT_EQ(host.pins[pin].secondary_tag, hm2::gtag::kInm) << pin;
    EXPECT_EQ(host.pins[pin].secondary_pin, static_cast<std::uint8_t>(pin + 1)) << "input, numbered from 1";
  }
  for (unsigned k = 0; k < 3; ++k) {
    EXPECT_EQ(host.pins[27 + k].secondary_tag, hm2::gtag::kEncoder);
    EXPECT_EQ(host.pins[27 + k].secondary_pin, static_cast<std::uint8_t>(k + 1)) << "A, B, index";
  }
  EXPECT_EQ(host.pins[30].secondary_tag, hm2::gtag::kSserial);
}

TEST_F(FeedbackBoard, Hostmot2sPeriodicReadSeesCountsTimestampsAndTheIndex) {
  VirtualBoard board(VirtualBoardOptions{}, t0);
  board.feedback().connect_axis(0, EncoderSpec{.counts_per_turn = 2000, .index_turns = 0.1}, HallSpec{},
                                turning);
  Host host(board, t0);
  namespace r = hm2::encoder_reg;
  host.write(host.address(hm2::gtag::kEncoder, r::kTimestampDivider), 48);  // 2 MHz
  host.write(host.address(hm2::gtag::kEncoder, r::kLatchControl), kArmIndex | hm2::encoder_bit::kFilter);
  const std::vector<std::uint16_t> period_reads{host.address(hm2::gtag::kEncoder, r::kTimestampCount),
                                                host.address(hm2::gtag::kEncoder, r::kCount),
                                                host.address(hm2::gtag::kEncoder, r::kLatchControl)};
  bool index_seen = false;
  for (int ms = 1; ms <= 30; ++ms) {
    host.at(std::chrono::milliseconds(ms) + 350us);
    const auto regs = host.read(period_reads);
    const auto tscount = static_cast<std::uint16_t>(regs[0]);
    const auto count = static_cast<std::uint16_t>(regs[1]);
    const auto timestamp = static_cast<std::uint16_t>(regs[1] >> 16);
    EXPECT_EQ(count, static_cast<std::uint16_t>(std::floor(10.0 * ms + 3.5))) << ms;
    // The last edge was less than one count period (100 us = 200 ticks) ago.
    EXPECT_LT(static_cast<std::uint16_t>(tscount - timestamp), 200) << ms;
    const bool armed = (regs[2] & hm2::encoder_bit::kLatchOnIndex) != 0;
    if (ms < 20) {
      EXPECT_TRUE(armed) << "bit 4 reads 1 until the index, at " << ms;
    }
    if (!armed && !index_seen) {
      index_seen = true;
      EXPECT_EQ(regs[2] >> 16, 201u) << "latched as Z fell (hm2's default index-invert 0)";
    }
  }
  EXPECT_TRUE(index_seen);
}

TEST_F(FeedbackBoard, HallsOnThe7i96sIsolatedInputsReadThroughInm) {
  VirtualBoard board(VirtualBoardOptions{}, t0);
  double angle = 0.0;
  const unsigned group = board.feedback().connect_axis(0, EncoderSpec{}, HallSpec{.pole_pairs = 4},
                                                       [&angle](Clock::time_point) { return angle; });
  Host host(board, t0);
  namespace r = hm2::inm_reg;
  // hostmot2 sets the global invert bit (inm.c: "matches all existing hardware").
  host.write(host.address(hm2::gtag::kInm, r::kControl), r::kGlobalInvert | 24u << 6 | 5u << 16 | 500u << 22);
  EXPECT_EQ(host.read(host.address(hm2::gtag::kInm, r::kControl)) & r::kMaxBitMask, 10u) << "11 inputs";
  const HallSensors reference(HallSpec{.pole_pairs = 4});
  for (int i = 0; i < 48; ++i) {
    angle = i / 48.0;
    const auto data = host.read(host.address(hm2::gtag::kInm, r::kFilteredData));
    EXPECT_EQ(data & 0x7u, input_bits(reference.code(angle))) << "inm.00.input-00..02 at " << angle;
    EXPECT_EQ(data & ~0x7u, 0u) << "inputs with nothing connected are inactive";
  }
  // A missing sensor drives no current: inactive, 0. A stuck-high one reads 1 everywhere.
  board.feedback().halls(group).set_fault(0, HallFault::Missing);
  board.feedback().halls(group).set_fault(1, HallFault::StuckHigh);
  for (int i = 0; i < 12; ++i) {
    angle = i / 12.0;
    const auto data = host.read(host.address(hm2::gtag::kInm, r::kRawData));
    EXPECT_EQ(data & 0x3u, 0x2u) << angle;
  }
}

TEST_F(FeedbackBoard, The7i92tServoConfigurationHasAnEncoderAndHallsPerAxis) {
  VirtualBoard board(VirtualBoardOptions{.config = BoardConfig::preset_7i92t_servo()}, t0);
  ASSERT_EQ(board.config().axes.size(), 4u);
  double angle = 0.0;
  const auto scripted = [&angle](Clock::time_point) { return angle; };
  const unsigned group = board.feedback().connect_axis(3, EncoderSpec{.counts_per_turn = 4000},
                                                       HallSpec{.pole_pairs = 2}, scripted);
  Host host(board, t0);
  EXPECT_EQ(host.module(hm2::gtag::kEncoder).instances, 4);
  EXPECT_EQ(host.module(hm2::gtag::kSserial).instances, 2);
  const AxisWiring& axis = board.config().axes[3];
  EXPECT_EQ(axis.encoder, 3u);
  EXPECT_EQ(axis.sserial_port, 1u);
  EXPECT_EQ(axis.channel, 1u);
  for (const unsigned pin : axis.hall_pins) EXPECT_EQ(host.pins[pin].secondary_tag, 0) << "GPIO";

  const HallSensors reference(HallSpec{.pole_pairs = 2});
  const unsigned port = axis.hall_pins[0] / host.idrom.port_width;
  const unsigned first_bit = axis.hall_pins[0] % host.idrom.port_width;
  const auto data_address = host.address(hm2::gtag::kIoPort, hm2::ioport_reg::kData, port);
  for (int step = 1; step <= 8; ++step) {
    host.at(std::chrono::milliseconds(step));
    angle = step * 0.1;
    EXPECT_EQ(host.read(host.address(hm2::gtag::kEncoder, hm2::encoder_reg::kCount, 3)) & 0xFFFF,
              static_cast<std::uint32_t>(std::floor(angle * 4000)));
    EXPECT_EQ(host.read(host.address(hm2::gtag::kEncoder, hm2::encoder_reg::kCount, 0)) & 0xFFFF, 0u)
        << "the other axes' encoders stand still";
    EXPECT_EQ(host.read(data_address) >> first_bit & 0x7u, input_bits(reference.code(angle)));
  }
  // A missing sensor floats: the 7I92T's pull-ups make it read high.
  board.feedback().halls(group).set_fault(2, HallFault::Missing);
  for (int i = 0; i < 12; ++i) {
    angle = i / 12.0;
    EXPECT_EQ(host.read(data_address) >> (first_bit + 2) & 1u, 1u) << angle;
  }
}

TEST_F(FeedbackBoard, GpioOutputsReadBackAndEncoderPinsShowTheirSignals) {
  VirtualBoard board(VirtualBoardOptions{}, t0);
  double angle = 0.0;
  board.feedback().connect_axis(0, EncoderSpec{.counts_per_turn = 2000}, HallSpec{},
                                [&angle](Clock::time_point) { return angle; });
  Host host(board, t0);
  namespace r = hm2::ioport_reg;
  // IO pins 27-29 are encoder 0's A, B, index: port 1, bits 10-12.
  const auto port1 = host.address(hm2::gtag::kIoPort, r::kData, 1);
  host.at(1ms);
  angle = 2.5 / 2000;  // quadrature state 2: A and B high
  EXPECT_EQ(host.read(port1) >> 10 & 0x3u, 0x3u);
  host.at(2ms);
  angle = 3.5 / 2000;  // state 3: B only
  EXPECT_EQ(host.read(port1) >> 10 & 0x3u, 0x2u);
  // Port 2 (the expansion connector): bit 0 an output driven high, bit 1 low, the rest pulled up.
  const auto port2 = host.address(hm2::gtag::kIoPort, r::kData, 2);
  host.write(host.address(hm2::gtag::kIoPort, r::kDirection, 2), 0x3);
  host.write(port2, 0x1);
  EXPECT_EQ(host.read(port2) & 0x7u, 0x5u);
  host.write(host.address(hm2::gtag::kIoPort, r::kOutputInvert, 2), 0x3);  // both outputs inverted
  EXPECT_EQ(host.read(port2) & 0x7u, 0x6u);
  EXPECT_EQ(board.hm2_register(port2), 0x1u) << "the written value stays visible to tests";
}

TEST_F(FeedbackBoard, EncoderRegistersOfEveryInstanceAnswer) {
  VirtualBoard board(VirtualBoardOptions{.config = BoardConfig::preset_7i92t_servo()}, t0);
  for (unsigned e = 0; e < 4; ++e)
    board.feedback().connect_encoder(e, EncoderSpec{.counts_per_turn = 1000 * static_cast<int>(e + 1)},
                                     [t0 = t0](Clock::time_point t) { return seconds(t - t0); });
  Host host(board, t0);
  host.at(250ms);
  for (unsigned e = 0; e < 4; ++e)
    EXPECT_EQ(host.read(host.address(hm2::gtag::kEncoder, hm2::encoder_reg::kCount, e)) & 0xFFFF,
              250u * (e + 1))
        << e;
  // Writing instance 2's count clears only it.
  host.write(host.address(hm2::gtag::kEncoder, hm2::encoder_reg::kCount, 2), 0);
  EXPECT_EQ(host.read(host.address(hm2::gtag::kEncoder, hm2::encoder_reg::kCount, 2)) & 0xFFFF, 0u);
  EXPECT_EQ(host.read(host.address(hm2::gtag::kEncoder, hm2::encoder_reg::kCount, 1)) & 0xFFFF, 500u);
  EXPECT_THROW(board.feedback().connect_encoder(4, EncoderSpec{}, nullptr), UsageError);
  EXPECT_THROW(board.feedback().connect_axis(4, EncoderSpec{}, HallSpec{}, nullptr), UsageError);
}
