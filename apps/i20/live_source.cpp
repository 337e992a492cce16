#include "live_source.hpp"

#include "eth/normal_mode.hpp"
#include "eth/target.hpp"

namespace i20::cli {
namespace {

class RegisterSource final : public LiveSource {
 public:
  explicit RegisterSource(Context& ctx) : ctx_(ctx) {}
  Readings read() override { return read_readings(ctx_.session().amp()); }
  std::string describe() override { return ctx_.session().link().describe(); }
  void reconnect() override { ctx_.session().reconnect(); }
  std::string method() const override { return "register reads"; }

 private:
  Context& ctx_;
};

class NormalModeSource final : public LiveSource {
 public:
  explicit NormalModeSource(eth::EthTarget target) : target_(std::move(target)) {}

  Readings read() override {
    if (!session_) session_ = eth::NormalModeSession::open(target_);
    const auto status = session_->wait_for_sample(std::chrono::milliseconds(500));
    const auto* ch = status.channel(target_.channel);
    if (!ch) throw Error("SSLBP normal mode returned no data for channel " + std::to_string(target_.channel));
    Readings r;
    r.fault = ch->fault;
    r.status = ch->status;
    r.busv_v = ch->bus_volts();
    r.temperature_c = ch->temperature_celsius();
    r.confirmed = true;  // INTERFACE0/1 carry these by definition: no RAM address involved
    return r;
  }
  std::string describe() override { return target_.describe() + " (SSLBP normal mode)"; }
  void reconnect() override { session_.reset(); }  // the destructor sends the SSLBP stop
  std::string method() const override { return "SSLBP normal mode (DOIT every 10 ms, QSETPOINT 0)"; }

 private:
  eth::EthTarget target_;
  std::unique_ptr<eth::NormalModeSession> session_;
};

eth::EthTarget eth_target(const app::GlobalOptions& o) {
  if (!o.eth.empty())
    return eth::is_eth_url(o.eth) ? eth::parse_target(o.eth)
                                  : eth::make_target(o.eth, o.channel, o.sserial_port);
  return eth::parse_target(o.port);
}

}  // namespace

bool is_eth_target(const app::GlobalOptions& o) {
  return !o.eth.empty() || eth::is_eth_url(o.port);
}

std::unique_ptr<LiveSource> make_live_source(Context& ctx, bool registers_only) {
  if (!registers_only && is_eth_target(ctx.options))
    return std::make_unique<NormalModeSource>(eth_target(ctx.options));
  return std::make_unique<RegisterSource>(ctx);
}

}  // namespace i20::cli
