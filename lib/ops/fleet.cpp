// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/fleet.hpp"

#include <map>
#include <thread>

#include "eth/passthrough_port.hpp"
#include "eth/target.hpp"
#include "link/wait_bound.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {

using Clock = std::chrono::steady_clock;
namespace {

// The channels of one SSERIAL port: one PassthroughPort serves them all, and their
// commands share DOITs (SSLBP's channel mask), so they run side by side.
struct EthPort {
  eth::HostPort host_port;
  unsigned sserial_port = 0;
  std::uint8_t mask = 0;
  std::vector<std::size_t> targets;
  std::shared_ptr<eth::PassthroughPort> port;
  std::string error;
  ErrorKind kind = ErrorKind::Failure;
  Advice advice = Advice::None;
};

std::vector<EthPort> by_port(const std::vector<Endpoint>& targets) {
  std::vector<EthPort> ports;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    if (!targets[i].is_eth()) continue;
    const auto t = targets[i].eth_target();
    auto it = std::find_if(ports.begin(), ports.end(), [&](const EthPort& p) {
      return p.host_port == t.host_port && p.sserial_port == t.sserial_port;
    });
    if (it == ports.end())
      it = ports.insert(ports.end(), EthPort{t.host_port, t.sserial_port, 0, {}, nullptr, {}, {}});
    it->mask = static_cast<std::uint8_t>(it->mask | t.channel_mask());
    it->targets.push_back(i);
  }
  return ports;
}

// Opened one after another before any thread starts; the ports of one card share its
// transport, or each would take the other's packets for another host's.
void open_ports(std::vector<EthPort>& ports, const OpenOptions& open, Clock::time_point started) {
  // Opening the ports counts against each target's deadline, as Amp::open's does.
  const link::WaitBound bounded(started + open.retry.operation_deadline);
  std::map<std::string, std::shared_ptr<eth::Lbp16Transport>> transports;
  for (auto& p : ports) {
    const eth::PassthroughOptions options = timing::passthrough(open.link, open.retry);
    try {
      auto& transport = transports[p.host_port.describe()];
      if (!transport)
        transport = eth::PassthroughPort::board_transport(p.host_port, options.udp, options.fence);
      p.port = eth::PassthroughPort::open(transport, p.sserial_port, p.mask, options);
    } catch (const Error& e) {
      p.error = e.what();
      p.kind = e.kind();
      p.advice = e.advice();
    }
  }
}

}  // namespace

void for_each_target(const std::vector<Endpoint>& targets, const params::ParamDb& db, const OpenOptions& open,
                     const Cancel& cancel, const FleetTask& task) {
  const auto started = Clock::now();
  auto ports = by_port(targets);
  open_ports(ports, open, started);
  std::vector<std::thread> threads;
  for (const auto& line : group_by_line(targets, false))
    threads.emplace_back([&, line] {
      for (const std::size_t i : line) task(i, [&, i] { return Amp::open(targets[i], db, open, cancel); });
    });
  for (const auto& p : ports)
    for (const std::size_t i : p.targets) {
      if (!p.port) {
        task(i, [&p]() -> std::unique_ptr<Amp> { throw Error(p.error, p.kind, p.advice); });
        continue;
      }
      const unsigned channel = targets[i].eth_target().channel;
      threads.emplace_back([&, i, channel, port = p.port] {
        task(i, [&, i, channel, port] {
          return Amp::attach(port->link(channel), targets[i], db, open.retry, cancel, started);
        });
      });
    }
  for (auto& t : threads) t.join();
}

std::vector<TargetRun> run_fleet(const std::vector<Endpoint>& targets, const ApplyJob& job,
                                 const FleetActivity& activity) {
  std::vector<TargetRun> runs(targets.size());
  for_each_target(targets, *job.db, job.open, job.transaction.cancel,
                  [&](std::size_t i, const AmpOpener& open) {
                    Activity one;
                    if (activity) one = [&activity, i](const std::string& s) { activity(i, s); };
                    runs[i] = run_apply_opened(targets[i], job, open, one);
                    if (activity) activity(i, to_string(runs[i].outcome));
                  });
  return runs;
}

}  // namespace i20::ops
