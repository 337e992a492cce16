// SPDX-License-Identifier: GPL-2.0-or-later
#include "console/server.hpp"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <deque>
#include <optional>
#include <vector>

#include "console/router.hpp"

namespace i20::console {
namespace {

namespace beast = boost::beast;
namespace net = boost::asio;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;

constexpr std::size_t kLiveBacklog = 8;        // samples a slow WebSocket client may lag behind
constexpr std::size_t kLiveMessageMax = 4096;  // the page sends nothing that needs more

}  // namespace

class LiveSocket;

struct Server::Impl {
  Impl(ServerOptions o, Api& api)
      : options(std::move(o)), router(Gate(options.token, {}, options.limits), options.static_dir, api) {}

  void accept();
  void tick_live();
  void tick_stop();
  void broadcast();

  net::io_context io{1};
  tcp::acceptor acceptor{io};
  net::steady_timer live_timer{io};
  net::steady_timer stop_timer{io};
  ServerOptions options;
  Router router;
  std::vector<std::weak_ptr<LiveSocket>> live;
  std::function<bool()> stop_requested;
};

// A WebSocket client of /api/live: receives samples, sends nothing the server reads.
class LiveSocket : public std::enable_shared_from_this<LiveSocket> {
 public:
  LiveSocket(beast::tcp_stream&& stream, Server::Impl& server) : ws_(std::move(stream)), server_(server) {}

  void accept(Request request) {
    beast::get_lowest_layer(ws_).expires_never();  // the WebSocket's own timeouts from here on
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(kLiveMessageMax);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->server_.live.push_back(self);
      self->read();
    });
  }

  // A slow client misses samples instead of making the server buffer them without bound.
  void push(const std::shared_ptr<const std::string>& text) {
    if (closed_ || queue_.size() >= kLiveBacklog) return;
    queue_.push_back(text);
    if (queue_.size() == 1) write();
  }
  bool closed() const { return closed_; }

 private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t n) {
      if (ec) {
        self->closed_ = true;
        return;
      }
      self->buffer_.consume(n);
      self->read();
    });
  }
  void write() {
    ws_.text(true);
    ws_.async_write(net::buffer(*queue_.front()),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      if (ec) {
                        self->closed_ = true;
                        return;
                      }
                      self->queue_.pop_front();
                      if (!self->queue_.empty()) self->write();
                    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  Server::Impl& server_;
  beast::flat_buffer buffer_;
  std::deque<std::shared_ptr<const std::string>> queue_;
  bool closed_ = false;
};

// One HTTP connection: requests in turn, each within the limits, until the client closes,
// goes idle, or is refused.
class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
 public:
  HttpConnection(tcp::socket socket, Server::Impl& server) : stream_(std::move(socket)), server_(server) {}

  void read() {
    const auto& limits = server_.options.limits;
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(limits.header_bytes));
    parser_->body_limit(limits.body_bytes);
    stream_.expires_after(server_.options.timing.idle);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

 private:
  void on_read(beast::error_code ec) {
    if (ec == http::error::end_of_stream || ec == beast::error::timeout ||
        ec == net::error::operation_aborted || ec == net::error::connection_reset)
      return close();
    if (ec == http::error::body_limit) {
      std::string message = "request body too large (at most ";
      message += std::to_string(server_.options.limits.body_bytes);
      message += " bytes)";
      return refuse(http::status::payload_too_large, message);
    }
    if (ec == http::error::header_limit)
      return refuse(http::status::request_header_fields_too_large, "request header too large");
    if (ec) return refuse(http::status::bad_request, "malformed request");
    auto request = parser_->release();
    if (websocket::is_upgrade(request)) return upgrade(std::move(request));
    send(server_.router.handle(request));
  }

  void upgrade(Request request) {
    if (auto refusal = server_.router.admit_upgrade(request)) return send(std::move(*refusal));
    std::make_shared<LiveSocket>(std::move(stream_), server_)->accept(std::move(request));
  }

  void refuse(http::status status, const std::string& message) {
    Request blank;
    blank.version(11);
    send(error_response(status, message, blank));
  }

  void send(Response response) {
    auto shared = std::make_shared<Response>(std::move(response));
    http::async_write(stream_, *shared,
                      [self = shared_from_this(), shared](beast::error_code ec, std::size_t) {
                        if (ec) return self->close();
                        if (!shared->keep_alive()) return self->drain();
                        self->read();
                      });
  }

  // After a refusal: stop sending, and read (and drop) what the client still sends, so that
  // closing with unread data does not reset the connection before it read the refusal.
  void drain() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    stream_.expires_after(server_.options.timing.drain);
    stream_.async_read_some(net::buffer(scratch_),
                            [self = shared_from_this()](beast::error_code ec, std::size_t) {
                              if (!ec) self->drain_more();
                            });
  }
  void drain_more() {
    stream_.async_read_some(net::buffer(scratch_),
                            [self = shared_from_this()](beast::error_code ec, std::size_t) {
                              if (!ec) self->drain_more();
                            });
  }

  void close() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
  }

  beast::tcp_stream stream_;
  Server::Impl& server_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::array<char, 4096> scratch_{};
};

void Server::Impl::accept() {
  acceptor.async_accept(io, [this](beast::error_code ec, tcp::socket socket) {
    if (!acceptor.is_open()) return;
    if (!ec) std::make_shared<HttpConnection>(std::move(socket), *this)->read();
    accept();
  });
}

void Server::Impl::broadcast() {
  std::erase_if(live, [](const std::weak_ptr<LiveSocket>& w) {
    const auto s = w.lock();
    return !s || s->closed();
  });
  if (live.empty()) return;  // no reader: the card is not asked
  const auto text = std::make_shared<const std::string>(router.api().live_sample());
  for (const auto& w : live)
    if (const auto s = w.lock()) s->push(text);
}

void Server::Impl::tick_live() {
  live_timer.expires_after(options.timing.live_interval);
  live_timer.async_wait([this](beast::error_code ec) {
    if (ec) return;
    broadcast();
    tick_live();
  });
}

void Server::Impl::tick_stop() {
  stop_timer.expires_after(options.timing.stop_poll);
  stop_timer.async_wait([this](beast::error_code ec) {
    if (ec) return;
    if (stop_requested && stop_requested()) return io.stop();
    tick_stop();
  });
}

std::string authority(const std::string& address, unsigned short port) {
  std::string text = address.find(':') != std::string::npos ? "[" + address + "]" : address;
  text += ":";
  text += std::to_string(port);
  return text;
}

Server::Server(ServerOptions options, Api& api) {
  if (options.token.empty()) options.token = make_token();
  impl_ = std::make_unique<Impl>(std::move(options), api);
  auto& o = impl_->options;
  const tcp::endpoint endpoint(net::ip::make_address(o.address), o.port);
  impl_->acceptor.open(endpoint.protocol());
  impl_->acceptor.set_option(net::socket_base::reuse_address(true));
  impl_->acceptor.bind(endpoint);
  impl_->acceptor.listen();
  // The Host values a browser sends for this address; "localhost" names loopback only.
  std::vector<std::string> authorities{authority(o.address, port())};
  if (net::ip::make_address(o.address).is_loopback()) authorities.push_back(authority("localhost", port()));
  impl_->router = Router(Gate(o.token, std::move(authorities), o.limits), o.static_dir, api);
}

Server::~Server() = default;

unsigned short Server::port() const {
  return impl_->acceptor.local_endpoint().port();
}
const std::string& Server::token() const {
  return impl_->options.token;
}

std::string Server::url() const {
  std::string url = "http://";
  url += authority(impl_->options.address, port());
  url += "/?token=";
  url += token();
  return url;
}

void Server::run(const std::function<bool()>& stop_requested) {
  impl_->stop_requested = stop_requested;
  impl_->accept();
  impl_->tick_live();
  impl_->tick_stop();
  impl_->io.run();
}

void Server::stop() {
  net::post(impl_->io, [impl = impl_.get()] { impl->io.stop(); });
}

}  // namespace i20::console
