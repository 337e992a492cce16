// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/feedback_bank.hpp"

#include <string>

#include "error/error.hpp"

namespace i20::ethsim {

namespace hm2 = lbp::hm2;

namespace {

std::optional<hm2::ModuleDescriptor> module_of(const BoardConfig& config, std::uint8_t gtag) {
  const hm2::ModuleDescriptor* m = config.find_module(gtag);
  return m ? std::optional(*m) : std::nullopt;
}

}  // namespace

FeedbackBank::FeedbackBank(const BoardConfig& config, Clock::time_point start)
    : idrom_(config.idrom),
      pins_(config.pins),
      axes_(config.axes),
      start_(start),
      encoder_module_(module_of(config, hm2::gtag::kEncoder)),
      ioport_module_(module_of(config, hm2::gtag::kIoPort)),
      inm_module_(module_of(config, hm2::gtag::kInm)),
      timestamp_(config.idrom.clock_low) {
  if (encoder_module_)
    for (unsigned i = 0; i < encoder_module_->instances; ++i)
      encoders_.push_back(Encoder{EncoderChannel(EncoderSpec{}), nullptr});
  if (ioport_module_) ports_.resize(ioport_module_->instances);
  if (inm_module_) {
    inms_.resize(inm_module_->instances);
    for (unsigned pin = 0; pin < pins_.size(); ++pin) {
      const hm2::PinDescriptor& d = pins_[pin];
      if (d.secondary_tag != hm2::gtag::kInm || d.secondary_unit >= inms_.size()) continue;
      const unsigned input = (d.secondary_pin & 0x7Fu) - 1u;
      auto& inputs = inms_[d.secondary_unit].input_pins;
      if (input >= 32) continue;
      if (inputs.size() <= input) inputs.resize(input + 1);
      inputs[input] = pin;
    }
  }
}

// ---- connections --------------------------------------------------------------------------

EncoderChannel& FeedbackBank::encoder(unsigned instance) {
  if (instance >= encoders_.size())
    throw UsageError("the virtual card has " + std::to_string(encoders_.size()) +
                     " encoder(s), not instance " + std::to_string(instance));
  return encoders_[instance].channel;
}

void FeedbackBank::connect_encoder(unsigned instance, EncoderSpec spec, ShaftSource shaft) {
  encoder(instance);  // checks the instance
  encoders_[instance] = Encoder{EncoderChannel(spec), std::move(shaft)};
  advanced_to_.reset();  // the new encoder is placed at the next access
}

unsigned FeedbackBank::connect_halls(std::array<unsigned, 3> io_pins, HallSpec spec, ShaftSource shaft) {
  for (const unsigned pin : io_pins)
    if (pin >= pins_.size())
      throw UsageError("the virtual card has " + std::to_string(pins_.size()) + " IO pins, not pin " +
                       std::to_string(pin));
  hall_groups_.push_back(HallGroup{HallSensors(spec), io_pins, std::move(shaft)});
  return static_cast<unsigned>(hall_groups_.size() - 1);
}

HallSensors& FeedbackBank::halls(unsigned group) {
  if (group >= hall_groups_.size()) throw UsageError("no Hall sensor group " + std::to_string(group));
  return hall_groups_[group].sensors;
}

unsigned FeedbackBank::connect_axis(unsigned axis, EncoderSpec encoder_spec, HallSpec hall_spec,
                                    ShaftSource shaft) {
  if (axis >= axes_.size())
    throw UsageError("the card configuration has " + std::to_string(axes_.size()) + " axis/axes, not axis " +
                     std::to_string(axis));
  const AxisWiring& wiring = axes_[axis];
  connect_encoder(wiring.encoder, encoder_spec, shaft);
  return connect_halls(wiring.hall_pins, hall_spec, std::move(shaft));
}

void FeedbackBank::advance(Clock::time_point now) {
  if (advanced_to_ == now) return;  // a packet's many reads share one sample
  advanced_to_ = now;
  for (Encoder& e : encoders_)
    if (e.shaft) e.channel.move_to(e.shaft(now), board_time(now), timestamp_);
}

// ---- pins ---------------------------------------------------------------------------------

bool FeedbackBank::is_inm_pin(unsigned pin) const {
  return pin < pins_.size() && pins_[pin].secondary_tag == hm2::gtag::kInm;
}

std::optional<HallOutput> FeedbackBank::hall_output(unsigned pin, Clock::time_point now) {
  for (const HallGroup& g : hall_groups_)
    for (unsigned k = 0; k < 3; ++k)
      if (g.pins[k] == pin) return g.sensors.outputs(g.shaft ? g.shaft(now) : 0.0)[k];
  return std::nullopt;
}

bool FeedbackBank::pin_level(unsigned pin, Clock::time_point now) {
  const std::optional<HallOutput> hall = hall_output(pin, now);
  if (is_inm_pin(pin)) {
    // An isolated input wired for a sourcing (PNP) sensor: a high output drives current
    // through the opto, which pulls the FPGA's input low. Nothing connected: no current.
    return !(hall && *hall == HallOutput::High);
  }
  if (hall) return *hall != HallOutput::Low;  // an open output is pulled up
  if (pin < pins_.size() && pins_[pin].secondary_tag == hm2::gtag::kEncoder) {
    const unsigned unit = pins_[pin].secondary_unit;
    if (unit < encoders_.size()) {
      const EncoderChannel& e = encoders_[unit].channel;
      switch (pins_[pin].secondary_pin & 0x7F) {
        case hm2::encoder_pin::kA: return e.a();
        case hm2::encoder_pin::kB: return e.b();
        case hm2::encoder_pin::kIndex: return e.z();
        default: break;
      }
    }
  }
  return true;  // pull-up
}

// ---- register dispatch --------------------------------------------------------------------

std::optional<std::uint32_t> FeedbackBank::read(std::uint16_t address, Clock::time_point now) {
  if (encoder_module_)
    if (const auto slot = encoder_module_->slot_at(idrom_, address)) {
      advance(now);
      return read_encoder(slot->reg, slot->instance, now);
    }
  if (ioport_module_)
    if (const auto slot = ioport_module_->slot_at(idrom_, address)) {
      advance(now);
      return read_port(slot->reg, slot->instance, now);
    }
  if (inm_module_)
    if (const auto slot = inm_module_->slot_at(idrom_, address))
      return read_inm(slot->reg, slot->instance, now);
  return std::nullopt;
}

bool FeedbackBank::write(std::uint16_t address, std::uint32_t value, Clock::time_point now) {
  if (encoder_module_)
    if (const auto slot = encoder_module_->slot_at(idrom_, address)) {
      advance(now);
      write_encoder(slot->reg, slot->instance, value, now);
      return true;
    }
  if (ioport_module_)
    if (const auto slot = ioport_module_->slot_at(idrom_, address)) {
      write_port(slot->reg, slot->instance, value);
      return true;
    }
  if (inm_module_)
    if (const auto slot = inm_module_->slot_at(idrom_, address)) {
      write_inm(slot->reg, slot->instance, value);
      return true;
    }
  return false;
}

std::optional<std::uint32_t> FeedbackBank::read_encoder(unsigned reg, unsigned instance,
                                                        Clock::time_point now) {
  namespace r = hm2::encoder_reg;
  switch (reg) {
    case r::kCount: return encoders_[instance].channel.count_register();
    case r::kLatchControl: return encoders_[instance].channel.latch_control_register();
    case r::kTimestampDivider: return timestamp_.divider_register();
    case r::kTimestampCount: return timestamp_.count_at(board_time(now));
    case r::kFilterRate: return filter_rate_;
    default: return std::nullopt;
  }
}

void FeedbackBank::write_encoder(unsigned reg, unsigned instance, std::uint32_t value,
                                 Clock::time_point now) {
  namespace r = hm2::encoder_reg;
  switch (reg) {
    case r::kCount: encoders_[instance].channel.write_count(); break;
    case r::kLatchControl: encoders_[instance].channel.write_latch_control(value); break;
    case r::kTimestampDivider: timestamp_.write_divider(value, board_time(now)); break;
    case r::kFilterRate: filter_rate_ = value & 0xFFFFu; break;
    default: break;  // TSCount is read only
  }
}

std::uint32_t FeedbackBank::read_port(unsigned reg, unsigned port, Clock::time_point now) {
  namespace r = hm2::ioport_reg;
  const Port& p = ports_[port];
  switch (reg) {
    case r::kData: {
      std::uint32_t levels = 0;
      const unsigned width = idrom_.port_width;
      for (unsigned bit = 0; bit < width && bit < 32; ++bit) {
        const std::uint32_t mask = 1u << bit;
        bool level = false;
        if ((p.direction & mask) != 0)
          // A GPIO output shows what it drives; a module's output (not simulated) reads low.
          level = (p.alt_source & mask) == 0 && ((p.data ^ p.invert) & mask) != 0;
        else
          level = pin_level(port * width + bit, now);
        if (level) levels |= mask;
      }
      return levels;
    }
    case r::kDirection: return p.direction;
    case r::kAltSource: return p.alt_source;
    case r::kOpenDrain: return p.open_drain;
    case r::kOutputInvert: return p.invert;
    default: return 0;
  }
}

void FeedbackBank::write_port(unsigned reg, unsigned port, std::uint32_t value) {
  namespace r = hm2::ioport_reg;
  Port& p = ports_[port];
  switch (reg) {
    case r::kData: p.data = value; break;
    case r::kDirection: p.direction = value; break;
    case r::kAltSource: p.alt_source = value; break;
    case r::kOpenDrain: p.open_drain = value; break;
    case r::kOutputInvert: p.invert = value; break;
    default: break;
  }
}

std::uint32_t FeedbackBank::inm_inputs(const Inm& inm, Clock::time_point now) {
  const bool invert = (inm.control & hm2::inm_reg::kGlobalInvert) != 0;
  std::uint32_t bits = 0;
  for (unsigned input = 0; input < inm.input_pins.size(); ++input) {
    const bool level = inm.input_pins[input] ? pin_level(*inm.input_pins[input], now) : true;
    if (level != invert) bits |= 1u << input;
  }
  return bits;
}

std::uint32_t FeedbackBank::read_inm(unsigned reg, unsigned instance, Clock::time_point now) {
  namespace r = hm2::inm_reg;
  const Inm& inm = inms_[instance];
  switch (reg) {
    case r::kControl: {
      const auto last_input =
          inm.input_pins.empty() ? 0u : static_cast<std::uint32_t>(inm.input_pins.size() - 1);
      return (inm.control & ~r::kMaxBitMask) | (last_input & r::kMaxBitMask);
    }
    case r::kFilter: return inm.filter;
    // No debounce: the filtered data is the raw data (docs/virtual-feedback.md).
    case r::kFilteredData:
    case r::kRawData: return inm_inputs(inm, now);
    default: return 0;  // the MPG counters do not count
  }
}

void FeedbackBank::write_inm(unsigned reg, unsigned instance, std::uint32_t value) {
  namespace r = hm2::inm_reg;
  Inm& inm = inms_[instance];
  if (reg == r::kControl) inm.control = value & ~r::kMaxBitMask;
  if (reg == r::kFilter) inm.filter = value;
}

}  // namespace i20::ethsim
