// SPDX-License-Identifier: GPL-2.0-or-later
// The Ethernet layers' options with the figures the programs use (ops/core/timing.hpp at the
// default --timeout and retry budget): the layers hold no counts or waits of their own, so a
// test that does not name its figures takes the programs'.
#pragma once

#include "eth/normal_mode.hpp"
#include "eth/passive_reader.hpp"
#include "eth/passthrough_port.hpp"
#include "eth/scan.hpp"
#include "ops/core/endpoint.hpp"
#include "ops/core/retry.hpp"
#include "ops/core/timing.hpp"

namespace i20::programs_timing {

inline eth::UdpOptions udp() {
  return ops::timing::udp({}, {});
}
inline eth::FenceOptions fence() {
  return ops::timing::fence();
}
inline eth::SslbpOptions sslbp() {
  return ops::timing::sslbp({});
}
inline eth::RunningHostCheck running_host() {
  return ops::timing::running_host({});
}
inline eth::PassthroughOptions passthrough() {
  return ops::timing::passthrough({}, {});
}
inline eth::ScanOptions scan() {
  return ops::timing::scan({}, {});
}
inline eth::PassiveOptions passive() {
  return ops::timing::passive({});
}
inline eth::NormalModeOptions normal_mode() {
  return ops::timing::normal_mode({});
}

}  // namespace i20::programs_timing
