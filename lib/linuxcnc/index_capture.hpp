// SPDX-License-Identifier: GPL-2.0-or-later
// The index, exact under bldc. bldc with an `i` in its cfg takes the rotor's index position
// from its rawcounts input in the servo period in which it finds index-enable cleared
// (bldc(9)); hostmot2 clears it in the read after the card saw the index, so by then the
// rotor has moved on by up to a period's travel, and the commutation keeps that error until
// the next power-up (docs/linuxcnc-hal.md, "The index under bldc"). hostmot2 itself resets
// the encoder's count at the index from the count the card latched there in hardware, so
// rawcounts - count is the rawcount at the index exactly. The capture hands bldc that value
// in the one period index-enable falls, and rawcounts itself in every other, from stock
// LinuxCNC components:
//   edge (falling)      index-enable -> one-period pulse
//   scaled_s32_sums     rawcounts - count (only its value in that period is used)
//   mux_generic ss2     rawcounts, or the sum during the pulse -> bldc.N.rawcounts
// The normal path is s32 throughout, so it wraps as rawcounts does.
#pragma once

#include <string>
#include <vector>

namespace i20::linuxcnc {

struct IndexCapture {
  std::string edge;  // edge instance (names=)
  std::string sum;   // scaled_s32_sums instance (names=)
  std::string mux;   // mux_generic instance, mux-gen.NN (numbered by its config string)
};

// The instances for one axis: `prefix` names the edge and sum ("j0-", "bldc0-"); `mux_number`
// is the axis's place in mux_generic's config string.
IndexCapture index_capture(const std::string& prefix, int mux_number);

// The loadrt lines for every capture, in order (one mux_generic config string for all).
std::string index_capture_loads(const std::vector<IndexCapture>& captures);

// The addf lines: after the board's read, before bldc's.
std::string index_capture_functions(const IndexCapture& capture, const std::string& thread = "servo-thread");

// The nets from `encoder` (hm2_....encoder.NN) to `bldc` (bldc.N), signals named from
// `signal_prefix`; `index_signal` is the signal that already joins the encoder's and bldc's
// index-enable pins.
std::string index_capture_nets(const IndexCapture& capture, const std::string& encoder,
                               const std::string& bldc, const std::string& signal_prefix,
                               const std::string& index_signal);

}  // namespace i20::linuxcnc
