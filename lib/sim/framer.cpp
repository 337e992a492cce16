// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/framer.hpp"

namespace i20::sim {

bool Framer::quiet_since_last_byte(Clock::time_point t) const {
  return last_byte_ && t - *last_byte_ > config_.timeout;
}

void Framer::push(lbp::Byte byte, Clock::time_point t) {
  if (config_.mode == FramingMode::Operate && !packet_.empty() && quiet_since_last_byte(t)) close_packet();
  if (resyncing_ && quiet_since_last_byte(t)) resyncing_ = false;
  const bool full = pending() >= config_.capacity;
  last_byte_ = t;  // a dropped byte still keeps the line busy
  if (resyncing_ || full) {
    overflow_ = overflow_ || full;
    ++dropped_;
    return;
  }
  if (config_.mode == FramingMode::Setup)
    splitter_.push(lbp::ByteView(&byte, 1));
  else
    packet_.push_back(byte);
}

std::optional<Framer::Frame> Framer::next(lbp::ByteView rpc_table) {
  if (config_.mode == FramingMode::Operate) {
    for (;;) {
      while (ready_.empty() && !closed_.empty()) {
        const lbp::Bytes packet = std::move(closed_.front());
        closed_.pop_front();
        queued_bytes_ -= packet.size();
        split_packet(packet, rpc_table);
      }
      if (ready_.empty()) return std::nullopt;
      Frame frame = std::move(ready_.front());
      ready_.pop_front();
      queued_bytes_ -= frame.command.size() + 1;
      if (still_fits(frame, rpc_table)) return frame;
      drop_rest_of_packet(frame);
    }
  }
  auto n = splitter_.next(rpc_table);
  switch (n.status) {
    case lbp::CommandSplitter::Status::Frame: return std::move(n.frame);
    case lbp::CommandSplitter::Status::NeedMore: return std::nullopt;
    case lbp::CommandSplitter::Status::Invalid: break;
  }
  // Garbage: everything buffered is suspect, and so is what follows until the line is quiet.
  dropped_ += splitter_.pending();
  splitter_.clear();
  resyncing_ = true;
  timeout_ = true;
  return std::nullopt;
}

void Framer::split_packet(const lbp::Bytes& packet, lbp::ByteView rpc_table) {
  lbp::CommandSplitter splitter;
  splitter.push(packet);
  std::deque<Frame> frames;
  for (;;) {
    auto n = splitter.next(rpc_table);
    if (n.status == lbp::CommandSplitter::Status::Frame) {
      frames.push_back(std::move(n.frame));
      continue;
    }
    if (n.status == lbp::CommandSplitter::Status::NeedMore && splitter.pending() == 0) break;
    // A partial command or garbage: the packet as a whole is not trusted.
    dropped_ += packet.size();
    timeout_ = true;
    return;
  }
  for (auto& f : frames) queued_bytes_ += f.command.size() + 1;
  ready_ = std::move(frames);
}

// The packet was split against the RPC table as it was when it arrived; a command before
// this one may have rewritten the table through RPCMEM. The card parses each command when
// its turn comes, so an RPC whose stored list now has another length (or no longer
// decodes) is not the command the bytes were cut for.
bool Framer::still_fits(const Frame& frame, lbp::ByteView rpc_table) {
  const auto shape = lbp::shape_of(frame.command.front(), rpc_table);
  return shape.ok && shape.shape == frame.shape;
}

void Framer::drop_rest_of_packet(const Frame& frame) {
  dropped_ += frame.command.size() + 1;
  for (const auto& f : ready_) {
    dropped_ += f.command.size() + 1;
    queued_bytes_ -= f.command.size() + 1;
  }
  ready_.clear();
  timeout_ = true;
}

void Framer::close_packet() {
  queued_bytes_ += packet_.size();
  closed_.push_back(std::move(packet_));
  packet_.clear();
}

void Framer::expire(Clock::time_point t) {
  if (!quiet_since_last_byte(t)) return;
  resyncing_ = false;
  if (config_.mode == FramingMode::Operate) {
    if (!packet_.empty()) close_packet();
    return;
  }
  if (splitter_.pending() > 0) {
    dropped_ += splitter_.pending();
    splitter_.clear();
    timeout_ = true;
  }
}

std::optional<Framer::Clock::time_point> Framer::deadline() const {
  const bool waiting =
      resyncing_ || (config_.mode == FramingMode::Setup ? splitter_.pending() > 0 : !packet_.empty());
  if (!waiting || !last_byte_) return std::nullopt;
  return *last_byte_ + config_.timeout + Clock::duration(1);
}

void Framer::clear() {
  splitter_.clear();
  packet_.clear();
  closed_.clear();
  ready_.clear();
  queued_bytes_ = 0;
  resyncing_ = false;
}

std::size_t Framer::pending() const {
  return config_.mode == FramingMode::Setup ? splitter_.pending() : packet_.size() + queued_bytes_;
}

}  // namespace i20::sim
