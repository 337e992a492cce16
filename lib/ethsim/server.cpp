// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/server.hpp"

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address_v4.hpp>
#include <boost/asio/ip/udp.hpp>

#include "error/error.hpp"
#include "ethsim/motor_feedback.hpp"
#include "ethsim/virtual_8i20_remote.hpp"

namespace i20::ethsim {

namespace asio = boost::asio;
using asio::ip::udp;
using Clock = std::chrono::steady_clock;

struct BoardServer::Socket {
  asio::io_context io;
  udp::socket socket{io};
  lbp::Bytes buffer = lbp::Bytes(65536);

  void wait_readable(Clock::time_point deadline) {
    bool ready = false;
    socket.async_wait(udp::socket::wait_read, [&](const boost::system::error_code& ec) { ready = !ec; });
    io.restart();
    io.run_until(deadline);
    if (!ready) {
      socket.cancel();
      io.restart();
      io.run();
    }
  }
};

namespace {

RemoteFactory amplifier_factory(const ServerOptions& options) {
  return [options](unsigned port, unsigned channel) -> std::unique_ptr<RemoteLbpDevice> {
    const auto& list = options.amplifiers;
    const auto it = std::find(list.begin(), list.end(), ChannelAddress{port, channel});
    if (it == list.end()) return nullptr;
    const auto index = static_cast<std::uint32_t>(it - list.begin());
    sim::DeviceOptions device = options.amplifier;
    device.mode = options.operate_mode ? sim::FramingMode::Operate : sim::FramingMode::Setup;
    device.amplifier.unit_number += index;
    device.amplifier.watchdog_set_by_host = true;  // SSLBP's normal start sets it
    if (device.eeprom_file && list.size() > 1)
      device.eeprom_file->replace_filename(device.eeprom_file->stem().string() + "-p" + std::to_string(port) +
                                           "c" + std::to_string(channel) +
                                           device.eeprom_file->extension().string());
    return std::make_unique<Virtual8i20Remote>(std::move(device), Clock::now());
  };
}

}  // namespace

eth::HostPort parse_listen_address(std::string_view text) {
  // ":0" asks the OS for a free port (tests, several simulators side by side); clients
  // can never address port 0, so parse_host_port rightly refuses it.
  if (text.size() > 2 && text.substr(text.size() - 2) == ":0") {
    auto address = eth::parse_host_port(text.substr(0, text.size() - 2));
    address.port = 0;
    return address;
  }
  return eth::parse_host_port(text);
}

BoardServer::BoardServer(ServerOptions options)
    : options_(std::move(options)), socket_(std::make_unique<Socket>()) {
  VirtualBoardOptions card;
  card.config = options_.config ? *options_.config : BoardConfig::preset(options_.card);
  card.sslbp = options_.sslbp;
  card.remotes = options_.remotes ? options_.remotes : amplifier_factory(options_);
  for (const auto& a : options_.amplifiers)
    if (!options_.remotes &&
        (a.port >= card.config.sserial_ports || a.channel >= card.config.channels_per_port))
      throw UsageError("the virtual " + std::string(board_kind_name(options_.card)) +
                       " has no SSERIAL port " + std::to_string(a.port) + " channel " +
                       std::to_string(a.channel));
  board_ = std::make_unique<VirtualBoard>(std::move(card), Clock::now());
  attach_motors();
  if (options_.host) start_host(*options_.host);

  eth::require_ipv4(options_.listen.ip);
  const udp::endpoint endpoint(asio::ip::make_address_v4(options_.listen.ip), options_.listen.port);
  boost::system::error_code ec;
  socket_->socket.open(udp::v4(), ec);
  if (!ec) socket_->socket.bind(endpoint, ec);
  if (ec)
    throw Error("cannot listen on UDP " + options_.listen.ip + ":" + std::to_string(options_.listen.port) +
                ": " + ec.message() + " (another card simulator running? use ADDR:PORT to pick another)");
  socket_->socket.non_blocking(true);
}

void BoardServer::attach_motors() {
  const auto now = Clock::now();
  for (const auto& m : options_.motors) {
    sim::Virtual8i20* amp = amplifier(*board_, 0, m.channel);
    if (!amp)
      throw UsageError("motor '" + m.name + "' sits on channel " + std::to_string(m.channel) +
                       ", which has no 8I20 on SSERIAL port 0");
    amp->amplifier().attach_motor(m, now);
    motor_axes_.push_back(
        MotorAxis{.channel = m.channel, .axis = connect_motor_feedback(*board_, *amp, 0, m.channel)});
  }
}

BoardServer::~BoardServer() {
  stop();
}

eth::HostPort BoardServer::address() const {
  const auto local = socket_->socket.local_endpoint();
  return eth::HostPort{.ip = local.address().to_string(), .port = local.port()};
}

std::string BoardServer::describe() const {
  const auto a = address();
  return "virtual " + board_->config().card_name + " at " + a.ip + ":" + std::to_string(a.port);
}

void BoardServer::start() {
  if (thread_.joinable()) return;
  stop_requested_ = false;
  thread_ = std::thread([this] { run(nullptr); });
}

void BoardServer::stop() {
  stop_requested_ = true;
  if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
}

void BoardServer::run(const std::atomic<bool>* stop_flag) {
  while (!stop_requested_ && !(stop_flag && stop_flag->load())) serve_once(Clock::now() + options_.tick);
}

void BoardServer::serve_once(Clock::time_point until) {
  {
    std::lock_guard lock(mutex_);
    if (host_) until = std::min(until, host_->next_due());
  }
  socket_->wait_readable(until);
  for (;;) {
    boost::system::error_code ec;
    udp::endpoint sender;
    const std::size_t n = socket_->socket.receive_from(asio::buffer(socket_->buffer), sender, 0, ec);
    if (ec) break;  // would block: nothing more queued
    std::optional<lbp::Bytes> reply;
    Clock::time_point ready;
    {
      std::lock_guard lock(mutex_);
      if (dark_until_) continue;  // a card without power hears nothing
      if (loss_rate_ > 0 && std::uniform_real_distribution<double>(0, 1)(loss_rng_) < loss_rate_) continue;
      reply = board_->handle(lbp::ByteView(socket_->buffer.data(), n), Clock::now());
      ready = board_->board_time();
    }
    if (!reply) continue;
    // A WaituS in the packet holds the reply back, as on the card.
    if (ready > Clock::now()) std::this_thread::sleep_until(ready);
    socket_->socket.send_to(asio::buffer(*reply), sender, 0, ec);
  }
  std::lock_guard lock(mutex_);
  if (dark_until_ && Clock::now() >= *dark_until_) {
    dark_until_.reset();
    for (unsigned p = 0; p < board_->sserial_ports(); ++p) board_->sslbp(p).power_on_reset(Clock::now());
    if (power_lost_)
      for (const auto& a : amplifiers())
        if (auto* amp = amplifier(*board_, a.port, a.channel)) amp->power_cycle(Clock::now());
    back_.notify_all();
  }
  if (dark_until_) return;
  board_->advance(Clock::now());
  if (host_) host_->run_until(*board_, Clock::now());
}

void BoardServer::go_dark(Clock::duration dark, bool power_loss) {
  std::lock_guard lock(mutex_);
  dark_until_ = Clock::now() + dark;
  power_lost_ = power_loss;
  host_.reset();  // the host's process sees the card go and stops driving it
  if (power_loss)
    for (const auto& a : amplifiers())
      if (auto* amp = amplifier(*board_, a.port, a.channel)) amp->power_off();
}

bool BoardServer::wait_until_back(Clock::duration timeout) {
  std::unique_lock lock(mutex_);
  return back_.wait_for(lock, timeout, [this] { return !dark_until_; });
}

void BoardServer::set_datagram_loss(double rate, std::uint32_t seed) {
  if (!(rate >= 0 && rate <= 1))
    throw UsageError("a datagram loss rate is 0..1, not " + std::to_string(rate));
  std::lock_guard lock(mutex_);
  loss_rate_ = rate;
  loss_rng_.seed(seed);
}

std::optional<HostStats> BoardServer::host_stats() {
  std::lock_guard lock(mutex_);
  if (!host_) return std::nullopt;
  return host_->stats();
}

bool BoardServer::host_running() {
  std::lock_guard lock(mutex_);
  return host_ && host_->running();
}

void BoardServer::start_host(HostOptions options) {
  std::lock_guard lock(mutex_);
  if (options.port >= board_->sserial_ports())
    throw UsageError("the virtual " + board_->config().card_name + " has no SSERIAL port " +
                     std::to_string(options.port));
  if (options.mask == 0)
    for (const auto& a : amplifiers())
      if (a.port == options.port) options.mask |= static_cast<std::uint8_t>(1u << a.channel);
  if (options.mask == 0) options.mask = 0x01;
  if (host_) host_->stop(*board_, Clock::now());
  host_.emplace(options);
}

void BoardServer::stop_host() {
  std::lock_guard lock(mutex_);
  if (host_) host_->stop(*board_, Clock::now());
  host_.reset();
}

std::optional<std::string> BoardServer::host_status() {
  std::lock_guard lock(mutex_);
  if (!host_) return std::nullopt;
  return host_->describe();
}

sim::Virtual8i20* BoardServer::amplifier(VirtualBoard& board, unsigned port, unsigned channel) {
  if (port >= board.sserial_ports() || channel >= board.config().channels_per_port) return nullptr;
  auto* remote = dynamic_cast<Virtual8i20Remote*>(board.sslbp(port).remote(channel));
  return remote ? &remote->device() : nullptr;
}

}  // namespace i20::ethsim
