// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/index_capture.hpp"

#include <sstream>

namespace i20::linuxcnc {

IndexCapture index_capture(const std::string& prefix, int mux_number) {
  // append(), not operator+: GCC 12's -O3 -Wrestrict misfires on `"0" + std::string&&`.
  std::string mux = "mux-gen.";
  mux.append(mux_number < 10 ? "0" : "").append(std::to_string(mux_number));
  return {prefix + "index-seen", prefix + "index-count", mux};
}

std::string index_capture_loads(const std::vector<IndexCapture>& captures) {
  if (captures.empty()) return {};
  std::string edges, sums, config;
  for (const auto& c : captures) {
    const char* comma = edges.empty() ? "" : ",";
    edges.append(comma).append(c.edge);
    sums.append(comma).append(c.sum);
    config.append(comma).append("ss2");
  }
  return "loadrt edge names=" + edges + "\nloadrt scaled_s32_sums names=" + sums +
         "\nloadrt mux_generic config=\"" + config + "\"\n";
}

std::string index_capture_functions(const IndexCapture& capture, const std::string& thread) {
  return "addf " + capture.edge + " " + thread + "\naddf " + capture.sum + " " + thread + "\naddf " +
         capture.mux + " " + thread + "\n";
}

std::string index_capture_nets(const IndexCapture& c, const std::string& encoder, const std::string& bldc,
                               const std::string& signal_prefix, const std::string& index_signal) {
  std::ostringstream out;
  out << "# The index, exact: in the period index-enable falls bldc reads the count at the index\n"
         "# (rawcounts - count; hostmot2 resets count there from the card's latch), else rawcounts.\n"
      << "setp " << c.edge << ".in-edge true   # falling\n"
      << "setp " << c.edge << ".out-width-ns 0   # one period\n"
      << "net " << index_signal << " => " << c.edge << ".in\n"
      << "net " << signal_prefix << "rawcounts " << encoder << ".rawcounts => " << c.sum << ".in0 " << c.mux
      << ".in-s32-00\n"
      << "net " << signal_prefix << "count " << encoder << ".count => " << c.sum << ".in1\n"
      << "setp " << c.sum << ".scale1 -1\n"
      << "net " << signal_prefix << "index-rawcounts " << c.sum << ".out-s => " << c.mux << ".in-s32-01\n"
      << "net " << signal_prefix << "index-seen " << c.edge << ".out => " << c.mux << ".sel-bit-00\n"
      << "net " << signal_prefix << "commutation-counts " << c.mux << ".out-s32 => " << bldc
      << ".rawcounts\n";
  return out.str();
}

}  // namespace i20::linuxcnc
