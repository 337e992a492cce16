// SPDX-License-Identifier: GPL-2.0-or-later
#include "commission/bldc_settings.hpp"

#include <cmath>

namespace i20::commission {

BldcSettings bldc_settings(const CommutationResult& result) {
  BldcSettings settings;
  if (result.hall.bldc_pattern) {
    settings.pattern = result.hall.bldc_pattern->value;
  } else if (result.hall.rewiring_to_25) {
    settings.pattern = 25;
    settings.hall_rewiring = result.hall.rewiring_to_25;
  } else {
    settings.missing.push_back("pattern: the Hall map was not found");
  }
  if (result.pole_pairs) {
    settings.poles = 2 * result.pole_pairs->value;
  } else {
    settings.missing.push_back("poles: the pole pairs were not found");
  }
  // bldc divides by scale/(poles/2) every period: a scale off by one count drifts the
  // commutation a little more every turn, so only an exact count will do.
  if (result.counts_per_turn && result.encoder_direction && result.counts_per_turn->uncertainty <= 0.5) {
    settings.scale = result.encoder_direction->value * std::llround(result.counts_per_turn->value);
  } else {
    settings.missing.push_back("scale: the exact counts per turn or the encoder direction were not found");
  }
  if (result.encoder_offset_counts) {
    settings.encoder_offset = result.encoder_offset_counts->value;
  } else {
    settings.missing.push_back("encoder-offset: the index's electrical angle was not found");
  }
  return settings;
}

}  // namespace i20::commission
