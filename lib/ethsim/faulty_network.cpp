// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/faulty_network.hpp"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address_v4.hpp>
#include <boost/asio/ip/udp.hpp>
#include <map>
#include <mutex>
#include <optional>
#include <queue>
#include <vector>

namespace i20::ethsim {

namespace asio = boost::asio;
using asio::ip::udp;
using Clock = std::chrono::steady_clock;

namespace {

// SplitMix64: a fixed function of (seed, direction, index), so a datagram's fate does not
// depend on the timing of the others.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

double unit(std::uint64_t seed, std::uint64_t direction, std::uint64_t index, std::uint64_t draw) {
  const std::uint64_t h = mix(mix(mix(seed) ^ direction) ^ (index * 8 + draw));
  return static_cast<double>(h >> 11) / static_cast<double>(1ull << 53);
}

}  // namespace

struct FaultyNetwork::Impl {
  struct Pending {
    Clock::time_point due;
    std::uint64_t order = 0;
    udp::socket* from = nullptr;
    udp::endpoint to;
    std::vector<std::uint8_t> bytes;
    bool operator>(const Pending& o) const { return due != o.due ? due > o.due : order > o.order; }
  };

  Impl(eth::HostPort card_address, NetworkFaults f)
      : card(asio::ip::make_address_v4(card_address.ip), card_address.port), faults(f) {
    front.open(udp::v4());
    front.bind(udp::endpoint(asio::ip::make_address_v4("127.0.0.1"), 0));
    front.non_blocking(true);
  }

  asio::io_context io;
  udp::socket front{io};
  udp::endpoint card;
  NetworkFaults faults;
  // One socket towards the card per client endpoint.
  std::map<udp::endpoint, std::unique_ptr<udp::socket>> backs;
  std::priority_queue<Pending, std::vector<Pending>, std::greater<>> queue;
  std::uint64_t order = 0;
  // Per direction, the datagram held back until the next one of its direction overtakes it.
  std::optional<Pending> overtaken[2];
  // The datagram hold_share holds until the next one of either direction has passed.
  std::optional<Pending> held_one;
  mutable std::mutex mutex;  // guards stats and the queue's size for idle()
  NetworkStats counted;
  std::size_t held = 0;
  std::atomic<std::uint64_t> passes{0};      // full passes over the sockets
  std::atomic<std::uint64_t> last_quiet{0};  // the latest pass that found nothing at all
  std::atomic<bool> stop{false};

  udp::socket& back_for(const udp::endpoint& client) {
    auto& s = backs[client];
    if (!s) {
      s = std::make_unique<udp::socket>(io);
      s->open(udp::v4());
      s->bind(udp::endpoint(asio::ip::make_address_v4("127.0.0.1"), 0));
      s->non_blocking(true);
    }
    return *s;
  }

  void schedule(udp::socket& from, const udp::endpoint& to, const std::vector<std::uint8_t>& bytes,
                Clock::duration delay) {
    queue.push(Pending{Clock::now() + delay, order++, &from, to, bytes});
  }

  std::chrono::microseconds delay_between(std::uint64_t dir, std::uint64_t index, std::uint64_t draw,
                                          std::chrono::milliseconds low) const {
    const double u = unit(faults.seed, dir, index, draw);
    const auto span = std::chrono::duration_cast<std::chrono::microseconds>(faults.max_delay - low);
    return std::chrono::duration_cast<std::chrono::microseconds>(low) +
           std::chrono::microseconds(static_cast<std::int64_t>(u * static_cast<double>(span.count())));
  }

  // Decides the fate of datagram `index` of direction `dir` (0: requests, 1: replies).
  void forward(std::uint64_t dir, std::uint64_t index, udp::socket& from, const udp::endpoint& to,
               const std::vector<std::uint8_t>& bytes) {
    std::lock_guard lock(mutex);  // the faults too: set_faults() and release_held() change them
    const bool spoil = dir == 0 ? faults.requests : faults.replies;
    (dir == 0 ? counted.requests : counted.replies)++;
    if (spoil && unit(faults.seed, dir, index, 0) < faults.drop_share) {
      ++counted.dropped;
      return;
    }
    if (spoil && bytes.size() > 1 && unit(faults.seed, dir, index, 5) < faults.truncate_share) {
      ++counted.truncated;
      const auto keep =
          static_cast<std::size_t>(unit(faults.seed, dir, index, 6) * static_cast<double>(bytes.size() - 1));
      const std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(keep));
      schedule(from, to, cut, Clock::duration{0});
      held = count_held();
      return;
    }
    if (spoil && !held_one && unit(faults.seed, dir, index, 8) < faults.hold_share) {
      ++counted.held;
      held_one = Pending{Clock::time_point::max(), order++, &from, to, bytes};
      held = count_held();
      return;
    }
    if (spoil && !overtaken[dir] && unit(faults.seed, dir, index, 7) < faults.reorder_share) {
      ++counted.reordered;
      overtaken[dir] = Pending{Clock::now() + faults.max_delay, order++, &from, to, bytes};
      held = count_held();
      return;
    }
    Clock::duration delay{0};
    if (spoil && unit(faults.seed, dir, index, 1) < faults.delay_share) {
      ++counted.delayed;
      delay = delay_between(dir, index, 2, faults.min_delay);
    }
    schedule(from, to, bytes, delay);
    if (spoil && unit(faults.seed, dir, index, 3) < faults.duplicate_share) {
      ++counted.duplicated;
      schedule(from, to, bytes, delay + delay_between(dir, index, 4, std::chrono::milliseconds{0}));
    }
    if (overtaken[dir]) {  // this one went first: the held one follows it
      overtaken[dir]->due = Clock::now() + delay;
      overtaken[dir]->order = order++;
      queue.push(std::move(*overtaken[dir]));
      overtaken[dir].reset();
    }
    if (held_one) release_held_one(delay);  // this one passed: the held one right after it
    held = count_held();
  }

  std::size_t count_held() const {
    return queue.size() + (overtaken[0] ? 1 : 0) + (overtaken[1] ? 1 : 0) + (held_one ? 1 : 0);
  }

  void release_held_one(Clock::duration delay) {
    held_one->due = Clock::now() + delay;
    held_one->order = order++;
    queue.push(std::move(*held_one));
    held_one.reset();
  }

  void release_due() {
    std::lock_guard lock(mutex);
    for (auto& o : overtaken)
      if (o && o->due <= Clock::now()) {  // nothing overtook it in time
        queue.push(std::move(*o));
        o.reset();
      }
    while (!queue.empty() && queue.top().due <= Clock::now()) {
      const Pending& p = queue.top();
      boost::system::error_code ec;
      p.from->send_to(asio::buffer(p.bytes), p.to, 0, ec);  // a closed client port is the client's loss
      queue.pop();
    }
    held = count_held();
  }

  bool idle_queue() const {
    std::lock_guard lock(mutex);
    return held == 0;
  }

  // Reads what is waiting on `socket`; false when nothing was.
  bool receive(udp::socket& socket, std::vector<std::uint8_t>& buffer, udp::endpoint& sender) {
    boost::system::error_code ec;
    buffer.resize(65536);
    const std::size_t n = socket.receive_from(asio::buffer(buffer), sender, 0, ec);
    if (ec) return false;
    buffer.resize(n);
    return true;
  }

  void loop() {
    std::uint64_t requests = 0, replies = 0;
    std::vector<std::uint8_t> buffer;
    while (!stop) {
      bool any = false;
      udp::endpoint sender;
      while (receive(front, buffer, sender)) {
        any = true;
        forward(0, requests++, back_for(sender), card, buffer);
      }
      for (auto& [client, back] : backs)
        while (receive(*back, buffer, sender)) {
          any = true;
          if (sender == card) forward(1, replies++, front, client, buffer);
        }
      release_due();
      const std::uint64_t pass = ++passes;
      if (!any) {
        if (idle_queue()) last_quiet = pass;
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    }
  }
};

FaultyNetwork::FaultyNetwork(eth::HostPort host_port, NetworkFaults faults)
    : impl_(std::make_unique<Impl>(std::move(host_port), faults)) {
  thread_ = std::thread([this] { impl_->loop(); });
}

FaultyNetwork::~FaultyNetwork() {
  impl_->stop = true;
  thread_.join();
}

std::string FaultyNetwork::address() const {
  return "127.0.0.1:" + std::to_string(impl_->front.local_endpoint().port());
}

bool FaultyNetwork::wait_idle(std::chrono::milliseconds limit) const {
  const auto deadline = Clock::now() + limit;
  const std::uint64_t asked = impl_->passes.load();
  // A pass that began after this call: its number exceeds the one running now by two.
  while (impl_->last_quiet.load() <= asked + 1) {
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

void FaultyNetwork::set_faults(const NetworkFaults& faults) {
  std::lock_guard lock(impl_->mutex);
  impl_->faults = faults;
}

void FaultyNetwork::release_held() {
  std::lock_guard lock(impl_->mutex);
  impl_->faults.hold_share = 0;
  if (impl_->held_one) impl_->release_held_one(Clock::duration{0});
  impl_->held = impl_->count_held();
}

NetworkStats FaultyNetwork::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->counted;
}

}  // namespace i20::ethsim
