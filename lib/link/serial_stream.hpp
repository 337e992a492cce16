// SPDX-License-Identifier: GPL-2.0-or-later
// A serial port (RS-422 through a USB adapter such as Mesa's 3I22, or a pseudo-terminal
// in tests) as a ByteStream: raw 8N1, no flow control, every call bounded by a deadline.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "link/byte_stream.hpp"
#include "link/given.hpp"

namespace i20::link {

struct SerialOptions {
  unsigned baud = 115200;  // setup mode is always 115200 (manual, "SETUP/OPERATE MODE")
  // Ask the driver to pass bytes on at once: ASYNC_LOW_LATENCY, and a 1 ms latency
  // timer on usb-serial adapters (FTDI default: 16 ms per reply).
  bool low_latency = true;
  // TIOCEXCL: a second program opening the port while we talk to the card gets EBUSY
  // instead of stealing half the replies.
  bool exclusive = true;
  std::filesystem::path sysfs_root = "/sys";  // where usb-serial latency timers live
  // How long past a write's wire time the driver may take before it counts as hung.
  Given<std::chrono::milliseconds> write_slack;
  // How long past its deadline a read or write may take to hand back control: asio needs a
  // moment to deliver the cancellation.
  Given<std::chrono::milliseconds> cancel_grace;
};

class SerialStream final : public ByteStream {
 public:
  using Options = SerialOptions;

  // Opens and configures the port. Throws LinkError naming the path and the likely fix.
  SerialStream(const std::string& path, Options options);
  ~SerialStream() override;
  SerialStream(const SerialStream&) = delete;
  SerialStream& operator=(const SerialStream&) = delete;

  void write(lbp::ByteView bytes) override;
  std::size_t read_some(std::span<lbp::Byte> buffer, Clock::time_point deadline) override;
  void discard_input() override;
  unsigned baud() const override;
  std::string name() const override;
  // What low-latency and exclusive-access set-up achieved, one line each.
  std::vector<std::string> notes() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Sets <sysfs_root>/bus/usb-serial/devices/<tty_name>/latency_timer to 1 ms when the file
// exists and is writable. Returns a one-line note saying what happened and, if it could
// not, why and how to fix it.
std::string tune_usb_latency_timer(const std::filesystem::path& sysfs_root, const std::string& tty_name);

}  // namespace i20::link
