// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/watch/live_source.hpp"

#include <algorithm>

#include "eth/normal_mode.hpp"
#include "eth/target.hpp"
#include "ops/core/errors.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {
namespace {

class RegisterSource final : public LiveSource {
 public:
  explicit RegisterSource(Session& session) : session_(session) {}
  // Each sample is an operation of its own: it gets the whole deadline (retry.hpp), however
  // long the watch has run.
  FaultReadings read() override {
    auto& amp = session_.amp();
    amp.restart_deadline();
    return read_fault_registers(amp);
  }
  std::string describe() override { return session_.endpoint().text; }
  void reconnect() override { session_.reconnect(); }
  std::string method() const override { return "register reads"; }

 private:
  Session& session_;
};

class NormalModeSource final : public LiveSource {
 public:
  NormalModeSource(eth::EthTarget target, const LinkSettings& link)
      : target_(std::move(target)), options_(timing::normal_mode(link)) {}

  FaultReadings read() override {
    if (!session_) session_ = eth::NormalModeSession::open(target_, options_);
    const auto status = session_->wait_for_sample(timing::kNormalModeSample);
    const auto* ch = status.channel(target_.channel);
    if (!ch) throw Error("SSLBP normal mode returned no data for channel " + std::to_string(target_.channel));
    FaultReadings r;
    r.fault = ch->fault;
    r.status = ch->status;
    r.busv_v = ch->bus_volts();
    r.temperature_c = ch->temperature_celsius();
    return r;
  }
  std::string describe() override { return target_.describe() + " (SSLBP normal mode)"; }
  void reconnect() override { session_.reset(); }  // the destructor sends the SSLBP stop
  std::string method() const override { return "SSLBP normal mode (DOIT every 10 ms, QSETPOINT 0)"; }

 private:
  eth::EthTarget target_;
  eth::NormalModeOptions options_;
  std::unique_ptr<eth::NormalModeSession> session_;
};

}  // namespace

bool is_eth_target(const Session& session) {
  const auto e = session.endpoint_if_any();
  return e && e->is_eth();
}

std::unique_ptr<LiveSource> make_live_source(Session& session, LiveMode mode) {
  if (mode == LiveMode::NormalModeOnEthernet && is_eth_target(session))
    return std::make_unique<NormalModeSource>(session.endpoint().eth_target(), session.options().link);
  return std::make_unique<RegisterSource>(session);
}

std::chrono::milliseconds retry_interval(std::chrono::milliseconds interval) {
  return std::max(interval, timing::kMonitorMinRetry);
}

LiveSampler::LiveSampler(LiveSource& source, std::chrono::milliseconds interval)
    : source_(source), retry_every_(retry_interval(interval)) {}

LiveSampler::Sample LiveSampler::next() {
  if (retry_at_ && Clock::now() < *retry_at_) return {std::nullopt, error_};
  try {
    Sample s{source_.read(), {}};
    retry_at_.reset();
    error_.clear();
    return s;
  } catch (const Cancelled&) {
    throw;
  } catch (const UsageError&) {
    throw;  // not the card's: nothing a retry mends
  } catch (const Error& e) {
    error_ = e.what();
    source_.reconnect();  // the port may have gone away with the adapter
    retry_at_ = Clock::now() + retry_every_;
    return {std::nullopt, error_};
  }
}

}  // namespace i20::ops
