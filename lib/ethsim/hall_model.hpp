// SPDX-License-Identifier: GPL-2.0-or-later
// Three Hall sensors on a motor's rotor, as a function of the rotor's mechanical angle
// (docs/virtual-feedback.md). Pure. The card decides what an open output reads as (a pulled-up
// GPIO pin reads high, an isolated input with no current reads inactive).
#pragma once

#include <array>
#include <cstdint>

namespace i20::ethsim {

enum class HallLayout {
  Spaced120,  // sensors 120 electrical degrees apart: codes 000 and 111 never occur
  Spaced60,   // sensors 60 degrees apart: 010 and 101 never occur
};

enum class HallFault { None, StuckHigh, StuckLow, Missing };

enum class HallOutput { Low, High, Open };

struct HallSpec {
  unsigned pole_pairs = 4;
  // Electrical angle (turns) at mechanical angle 0: electrical = pole_pairs x mechanical +
  // this. Use the motor model's own value so the Halls agree with its torque.
  double electrical_offset_turns = 0.0;
  // Electrical angle (turns) where sensor 1 goes high; sensor k (k = 0, 1, 2) is high for
  // half an electrical turn from here + k x spacing. The default, 30 degrees with the 120
  // degree layout, gives the codes of bldc's default `pattern` 25 with its sector centres:
  // 001 at 0, 101 at 60, 100 at 120, 110 at 180, 010 at 240, 011 at 300 degrees.
  double first_rise_turns = 1.0 / 12.0;
  HallLayout layout = HallLayout::Spaced120;
  // Polarity: every sensor's output inverted (high where the description says low).
  bool inverted = false;
  // Wiring: card input k carries sensor order[k] (a swapped pair reverses the sequence).
  std::array<unsigned, 3> order{0, 1, 2};
};

class HallSensors {
 public:
  explicit HallSensors(HallSpec spec);  // throws UsageError on a bad spec

  // The three outputs, in input order, with the rotor at `mechanical_turns`.
  std::array<HallOutput, 3> outputs(double mechanical_turns) const;
  // Outputs as H1 H2 H3 bits (H1 = bit 2, as bldc indexes its table), an open output
  // counted as `open_reads`.
  unsigned code(double mechanical_turns, bool open_reads = true) const;
  double electrical_turns(double mechanical_turns) const;

  // A fault on card input `input` (0-2): stuck high/low, or missing (open).
  void set_fault(unsigned input, HallFault fault);
  HallFault fault(unsigned input) const { return faults_.at(input); }
  const HallSpec& spec() const { return spec_; }

 private:
  HallSpec spec_;
  std::array<HallFault, 3> faults_{};
};

}  // namespace i20::ethsim
