// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual card's feedback modules behind their HostMot2 registers: the quadrature
// counters (GTag 4), the GPIO ports (GTag 3) and the InM input module (GTag 35), at the
// addresses the card's IDROM declares, for every instance. Encoders and Hall sensors
// follow a shaft: a function giving the rotor's mechanical angle in turns (unwrapped) at a
// card time, so a test can script the angle and a motor model can stand behind it.
//
//   card.feedback().connect_axis(0, EncoderSpec{.counts_per_turn = 4000}, HallSpec{},
//                                [&motor](Clock::time_point t) { return motor.turns_at(t); });
//
// The shaft is sampled whenever the card's time advances (every server tick) and at each
// feedback register access; between samples it is taken to turn at a constant speed, so
// encoder edges get the times they would have had (docs/virtual-feedback.md). Under
// BoardServer the shaft is called on the server's thread while it holds the card (the lock
// with_card() takes), so connect shafts inside with_card() and make them safe to call there.
// A shaft may be asked several times for the same time point and must answer the same.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "ethsim/board_config.hpp"
#include "ethsim/encoder_model.hpp"
#include "ethsim/hall_model.hpp"
#include "ethsim/remote_device.hpp"

namespace i20::ethsim {

// The rotor's mechanical angle in turns (unwrapped) at a card time.
using ShaftSource = std::function<double(Clock::time_point)>;

class FeedbackBank {
 public:
  FeedbackBank(const BoardConfig& config, Clock::time_point start);

  // A feedback register's value at `now`, or nullopt when `address` is none of them.
  std::optional<std::uint32_t> read(std::uint16_t address, Clock::time_point now);
  // Applies a host write at `now`; false when `address` is none of the feedback registers.
  bool write(std::uint16_t address, std::uint32_t value, Clock::time_point now);
  // Samples every shaft at `now` and steps the encoders to it.
  void advance(Clock::time_point now);

  unsigned encoder_count() const { return static_cast<unsigned>(encoders_.size()); }
  EncoderChannel& encoder(unsigned instance);
  // Encoder instance `instance` follows `shaft` (replacing what it had).
  void connect_encoder(unsigned instance, EncoderSpec spec, ShaftSource shaft);
  // Three Hall sensors on the card's IO pins `io_pins` (IDROM pin numbers: an InM input
  // or a GPIO pin) follow `shaft`. Returns the group's number for halls().
  unsigned connect_halls(std::array<unsigned, 3> io_pins, HallSpec spec, ShaftSource shaft);
  HallSensors& halls(unsigned group);
  // Axis `axis` of the card configuration: its encoder and its Halls follow `shaft`.
  // Returns the Hall group's number.
  unsigned connect_axis(unsigned axis, EncoderSpec encoder, HallSpec halls, ShaftSource shaft);

  // The level the FPGA sees on IO pin `pin` now (GPIO pull-ups read high; an isolated input
  // reads low while current flows, i.e. while it is active).
  bool pin_level(unsigned pin, Clock::time_point now);

 private:
  struct Encoder {
    EncoderChannel channel;
    ShaftSource shaft;
  };
  struct HallGroup {
    HallSensors sensors;
    std::array<unsigned, 3> pins;
    ShaftSource shaft;
  };
  struct Port {
    std::uint32_t data = 0, direction = 0, alt_source = 0, open_drain = 0, invert = 0;
  };
  struct Inm {
    std::uint32_t control = 0, filter = 0;
    std::vector<std::optional<unsigned>> input_pins;  // input number -> IO pin
  };

  BoardTime board_time(Clock::time_point now) const { return now - start_; }
  std::optional<std::uint32_t> read_encoder(unsigned reg, unsigned instance, Clock::time_point now);
  void write_encoder(unsigned reg, unsigned instance, std::uint32_t value, Clock::time_point now);
  std::uint32_t read_port(unsigned reg, unsigned port, Clock::time_point now);
  void write_port(unsigned reg, unsigned port, std::uint32_t value);
  std::uint32_t read_inm(unsigned reg, unsigned instance, Clock::time_point now);
  void write_inm(unsigned reg, unsigned instance, std::uint32_t value);
  std::uint32_t inm_inputs(const Inm& inm, Clock::time_point now);
  bool is_inm_pin(unsigned pin) const;
  std::optional<HallOutput> hall_output(unsigned pin, Clock::time_point now);

  lbp::hm2::Idrom idrom_;
  std::vector<lbp::hm2::PinDescriptor> pins_;
  std::vector<AxisWiring> axes_;
  Clock::time_point start_;
  std::optional<lbp::hm2::ModuleDescriptor> encoder_module_, ioport_module_, inm_module_;
  TimestampCounter timestamp_;
  std::uint32_t filter_rate_ = 0;
  std::optional<Clock::time_point> advanced_to_;  // the encoders' last sample time
  std::vector<Encoder> encoders_;
  std::vector<HallGroup> hall_groups_;
  std::vector<Port> ports_;
  std::vector<Inm> inms_;
};

}  // namespace i20::ethsim
