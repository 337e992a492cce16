// SPDX-License-Identifier: GPL-2.0-or-later
// Motor files (lib/motor/loader, motors/README.md) as i20sim --motor reads them, and a
// motor the loader accepted: it turns for a few periods with finite numbers and reads its
// sensors, so validation is what keeps the model sane.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "fuzz_support.hpp"
#include "motor/loader.hpp"
#include "motor/motor.hpp"
#include "params/text.hpp"

namespace {

using namespace i20;

void accepted(const motor::MotorParams& params) {
  fuzz::require(!params::control_character(params.name), "an accepted motor's name prints safely");
  motor::Motor m(params);
  motor::DriveCommand drive;
  drive.output_on = true;
  drive.frame_follows_rotor = true;
  drive.current_a = {0.0, 1.0};
  drive.bus_voltage_v = 48;
  m.command(drive);
  for (int i = 0; i < 20; ++i) m.step(m.period_s());
  fuzz::require(std::isfinite(m.state().speed_rad_s) && std::isfinite(m.state().angle_turns),
                "an accepted motor keeps finite speed and angle");
  (void)m.read_sensors();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::optional<motor::MotorParams> loaded;
  fuzz::expect_only_toolkit_errors(
      [&] { loaded = motor::parse_motor(fuzz::text_of(data, size), "fuzz.yaml"); });
  if (loaded) fuzz::expect_no_exception([&] { accepted(*loaded); });
  return 0;
}
