// SPDX-License-Identifier: GPL-2.0-or-later
#include "live_source.hpp"

#include "eth/normal_mode.hpp"
#include "eth/target.hpp"

namespace i20::cli {
namespace {

class RegisterSource final : public LiveSource {
 public:
  explicit RegisterSource(Context& ctx) : ctx_(ctx) {}
  Readings read() override { return ops::read_fault_registers(ctx_.card()); }
  std::string describe() override { return ctx_.session().endpoint().text; }
  void reconnect() override { ctx_.session().reconnect(); }
  std::string method() const override { return "register reads"; }

 private:
  Context& ctx_;
};

class NormalModeSource final : public LiveSource {
 public:
  NormalModeSource(eth::EthTarget target, bool take_over) : target_(std::move(target)) {
    options_.running_host.take_over = take_over;
  }

  Readings read() override {
    if (!session_) session_ = eth::NormalModeSession::open(target_, options_);
    const auto status = session_->wait_for_sample(std::chrono::milliseconds(500));
    const auto* ch = status.channel(target_.channel);
    if (!ch) throw Error("SSLBP normal mode returned no data for channel " + std::to_string(target_.channel));
    Readings r;
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

bool is_eth_target(const app::GlobalOptions& o) {
  const auto e = ops::endpoint_from(o.target);
  return e && e->is_eth();
}

std::unique_ptr<LiveSource> make_live_source(Context& ctx, LiveMode mode) {
  if (mode == LiveMode::NormalModeOnEthernet && is_eth_target(ctx.options))
    return std::make_unique<NormalModeSource>(eth::parse_target(ctx.session().endpoint().eth_url),
                                              ctx.options.link.take_over);
  return std::make_unique<RegisterSource>(ctx);
}

}  // namespace i20::cli
