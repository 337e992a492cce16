// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 commission` on the virtual axis, timed: the 400 W servo of motors/servo-halls-index.yaml
// (4 pole pairs, 10000 counts, Halls, index) behind a virtual 7I92T over loopback UDP, with
// the index at several angles. Prints the commissioning time, the error of the index's
// electrical angle found (what encoder-offset is made of) against the simulator's truth, and
// the host loop's DOIT period (p50, p99, worst). SIMULATED: the card, the 8I20 and the motor
// are models; the DOIT timing is this machine's.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>

#include "build_paths.hpp"
#include "ethsim/server.hpp"
#include "motor/loader.hpp"
#include "ops/commission/commission.hpp"
#include "ops/core/session.hpp"

using namespace i20;

namespace {

motor::MotorParams servo(double index_deg) {
  std::ifstream in(i20::test::source_dir() / "motors/servo-halls-index.yaml");
  std::stringstream text;
  text << in.rdbuf();
  auto params = motor::parse_motor(text.str(), "servo-halls-index.yaml");
  params.channel = 0;
  params.encoder->index_angle_rad = index_deg * std::numbers::pi / 180.0;
  return params;
}

struct Figures {
  ops::CommissionReport report;
  double error_deg = 0;
};

Figures run(double index_deg, const ops::CommissionOptions& options) {
  const auto params = servo(index_deg);
  ethsim::ServerOptions so;
  so.listen = eth::HostPort{.ip = "127.0.0.1", .port = 0};
  so.card = ethsim::BoardKind::I7i92t;
  so.config = ethsim::BoardConfig::preset_7i92t_servo();
  so.motors = {params};
  ethsim::BoardServer server(so);
  server.start();
  ops::SessionOptions session_options;
  session_options.target.eth = "127.0.0.1:";
  session_options.target.eth += std::to_string(server.address().port);
  ops::Session session(session_options);
  const auto plan = ops::prepare_commission(session, options);
  Figures f;
  f.report = ops::run_commission(session, plan, options);
  server.stop();
  const double truth = std::fmod(params.pole_pairs * index_deg, 360.0);
  if (f.report.result && f.report.result->index_electrical_angle_deg)
    f.error_deg = std::remainder(f.report.result->index_electrical_angle_deg->value - truth, 360.0);
  else
    f.error_deg = NAN;
  return f;
}

double ms(std::chrono::microseconds us) {
  return static_cast<double>(us.count()) / 1000.0;
}

}  // namespace

int main() {
  std::printf("i20 commission on the virtual axis (SIMULATED card, 8I20 and motor; real UDP and timing)\n");
  std::printf("motor: 400 W servo, 4 pole pairs, 10000 counts/turn, Halls (pattern 25), index\n\n");
  std::printf("%-34s %9s %7s %9s %8s %8s %8s %5s\n", "run", "time s", "result", "err deg", "p50 ms", "p99 ms",
              "worst ms", "late");
  double worst_error = 0, worst_time = 0, worst_gap = 0;
  for (const bool given : {false, true})
    for (const double index_deg : {0.0, 30.0, 77.7, 201.3}) {
      ops::CommissionOptions o;  // the defaults a user gets
      if (given) {
        o.pole_pairs = 4;
        o.counts_per_turn = 10000;
      }
      const auto f = run(index_deg, o);
      const auto& r = f.report;
      char label[64];
      std::snprintf(label, sizeof label, "%s, index %.1f deg",
                    given ? "--poles 8 --counts-per-rev 10000" : "nothing given", index_deg);
      std::printf("%-34s %9.1f %7s %9.2f %8.1f %8.1f %8.1f %5llu\n", label, r.elapsed_s,
                  std::string(ops::stop_reason_name(r.stop)).substr(0, 7).c_str(), f.error_deg,
                  ms(r.doit.percentile(50)), ms(r.doit.percentile(99)), ms(r.doit.worst()),
                  static_cast<unsigned long long>(r.doit.late));
      worst_error = std::max(worst_error, std::abs(f.error_deg));
      worst_time = std::max(worst_time, r.elapsed_s);
      worst_gap = std::max(worst_gap, ms(r.doit.worst()));
    }
  std::printf(
      "\nworst: time %.1f s (goal < 30 s), offset error %.2f electrical deg (goal < 2), DOIT gap %.1f ms "
      "(watchdog 40 ms)\n",
      worst_time, worst_error, worst_gap);
}
