// SPDX-License-Identifier: GPL-2.0-or-later
// A sim::Virtual8i20 behind one SSLBP channel of the virtual card.
#pragma once

#include <memory>

#include "ethsim/remote_device.hpp"
#include "sim/virtual_8i20.hpp"

namespace i20::ethsim {

class Virtual8i20Remote final : public RemoteLbpDevice {
 public:
  explicit Virtual8i20Remote(sim::DeviceOptions options = default_options(),
                             Clock::time_point power_on = Clock::now());

  Exchange exchange(lbp::ByteView framed_command, std::size_t reply_wire_bytes, Clock::time_point now,
                    Clock::duration timeout) override;
  void advance(Clock::time_point now) override;
  // CLEARFAULT = 1 and QSETPOINT = 0 at the addresses of the card's register map.
  std::vector<lbp::Command> normal_start_commands() const override;
  void normal_started() override;
  std::string describe() const override;

  sim::Virtual8i20& device() { return device_; }
  const sim::Virtual8i20& device() const { return device_; }

  // An 8I20 on a running machine: operate mode (2.5 MBaud, watchdog armed), unit
  // number from the amplifier defaults.
  static sim::DeviceOptions default_options();

 private:
  sim::Virtual8i20 device_;
};

}  // namespace i20::ethsim
