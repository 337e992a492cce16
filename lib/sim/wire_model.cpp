// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/wire_model.hpp"

#include <algorithm>

namespace i20::sim {

void WireModel::host_write(lbp::ByteView bytes, Clock::time_point now) {
  if (!options_.emulate_wire_time) {
    pump(now);
    card_.receive(bytes, now);
    card_time_ = std::max(card_time_, now);
    collect_output(now);
    return;
  }
  Clock::time_point t = std::max(line_to_card_free_, now);
  const auto byte_time = card_.character_time();
  for (lbp::Byte b : bytes) {
    t += byte_time;
    to_card_.push_back({t, b});
  }
  line_to_card_free_ = t;
}

void WireModel::pump(Clock::time_point now) {
  // Step through arrivals and the card's own events in time order, so each reply is
  // stamped with the moment the card produced it, not the moment we looked.
  for (;;) {
    std::optional<Clock::time_point> event = card_.next_event();
    if (event && *event <= card_time_) event.reset();  // nothing new: guard against stalls
    const bool byte_first = !to_card_.empty() && (!event || to_card_.front().at <= *event);
    const Clock::time_point t = byte_first ? to_card_.front().at : event.value_or(now + Duration(1));
    if (t > now) break;
    if (byte_first) {
      const lbp::Byte b = to_card_.front().byte;
      to_card_.pop_front();
      card_.receive(lbp::ByteView(&b, 1), t);
    } else {
      card_.advance(t);
    }
    card_time_ = std::max(card_time_, t);
    collect_output(t);
  }
  card_.advance(now);
  card_time_ = std::max(card_time_, now);
  collect_output(now);
}

void WireModel::collect_output(Clock::time_point t) {
  const lbp::Bytes out = card_.take_output();
  if (out.empty()) return;
  Clock::time_point at = t + options_.turnaround;
  if (!options_.emulate_wire_time) {
    for (lbp::Byte b : out) to_host_.push_back({at, b});
    return;
  }
  at = std::max(at, line_to_host_free_);
  const auto byte_time = card_.character_time();
  for (lbp::Byte b : out) {
    at += byte_time;
    to_host_.push_back({at, b});
  }
  line_to_host_free_ = at;
}

std::size_t WireModel::host_read(std::span<lbp::Byte> buffer, Clock::time_point now) {
  std::size_t n = 0;
  while (n < buffer.size() && !to_host_.empty() && to_host_.front().at <= now) {
    buffer[n++] = to_host_.front().byte;
    to_host_.pop_front();
  }
  return n;
}

void WireModel::discard_host_input(Clock::time_point now) {
  while (!to_host_.empty() && to_host_.front().at <= now) to_host_.pop_front();
}

std::optional<Clock::time_point> WireModel::next_wake() const {
  std::optional<Clock::time_point> next = card_.next_event();
  if (next && *next <= card_time_) next.reset();  // already handled by the last pump()
  const auto consider = [&](Clock::time_point t) {
    if (!next || t < *next) next = t;
  };
  if (!to_card_.empty()) consider(to_card_.front().at);
  if (!to_host_.empty()) consider(to_host_.front().at);
  return next;
}

}  // namespace i20::sim
