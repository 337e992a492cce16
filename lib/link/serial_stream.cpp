// SPDX-License-Identifier: GPL-2.0-or-later
#include "link/serial_stream.hpp"

#include <fcntl.h>
#include <linux/serial.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/serial_port.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

#include "link/link.hpp"

namespace i20::link {
namespace asio = boost::asio;
namespace fs = std::filesystem;
using boost::system::error_code;

namespace {

std::string errno_text(int error) {
  return std::generic_category().message(error);
}

// One line a person can act on, for the errors opening a port usually hits.
std::string open_failure(const std::string& path, const error_code& ec) {
  const int e = ec.value();
  if (e == EACCES || e == EPERM)
    return "permission denied opening " + path +
           ": add your user to the dialout group (sudo usermod -aG dialout $USER) and log in again";
  if (e == ENOENT || e == ENODEV || e == ENXIO)
    return path +
           " does not exist: is the USB serial adapter (e.g. 3I22) plugged in? List the serial "
           "ports to find the right one";
  if (e == EBUSY)
    return path +
           " is in use by another program (a terminal program, ModemManager, another i20): close it "
           "and try again";
  if (e == ENOTTY) return path + " is not a serial port";
  return "cannot open " + path + ": " + ec.message();
}

// "/dev/serial/by-id/usb-FTDI_..." -> "ttyUSB0"; "/dev/pts/3" -> "pts/3".
std::string tty_name(const std::string& path) {
  std::error_code ec;
  const auto device = fs::canonical(path, ec);
  if (ec) return fs::path(path).filename().string();
  const auto relative = device.lexically_relative("/dev");
  return relative.empty() || *relative.begin() == ".." ? device.filename().string() : relative.string();
}

// Who holds the flock on this open file, from /proc/locks ("1: FLOCK  ADVISORY  WRITE 1234
// 00:19:5 0 EOF": the pid, then the device as hex major:minor and the inode).
std::string lock_holder(int fd) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return {};
  std::ifstream locks("/proc/locks");
  std::string line;
  while (std::getline(locks, line)) {
    std::istringstream in(line);
    std::string id, kind, advisory, mode, where;
    long pid = 0;
    if (!(in >> id >> kind >> advisory >> mode >> pid >> where) || kind != "FLOCK") continue;
    unsigned major_no = 0, minor_no = 0;
    unsigned long long inode = 0;
    if (std::sscanf(where.c_str(), "%x:%x:%llu", &major_no, &minor_no, &inode) != 3) continue;
    if (inode != st.st_ino || major_no != major(st.st_dev) || minor_no != minor(st.st_dev)) continue;
    std::string name;
    std::ifstream(("/proc/" + std::to_string(pid) + "/comm").c_str()) >> name;
    return "PID " + std::to_string(pid) + (name.empty() ? "" : " (" + name + ")");
  }
  return {};
}

}  // namespace

struct SerialStream::Impl {
  Impl(std::string path_, Options options_) : path(std::move(path_)), options(std::move(options_)) {}
  std::string path;
  Options options;
  asio::io_context io;
  asio::serial_port port{io};
  asio::steady_timer timer{io};
  std::vector<std::string> notes;

  int fd() { return port.native_handle(); }
  void open();
  void configure();
  void lock();
  void request_exclusive();
  void request_low_latency();
  void run_until_done(const bool& op_done, const bool& timer_done, Clock::time_point deadline);
};

void SerialStream::Impl::open() {
  error_code ec;
  port.open(path, ec);
  if (ec) throw LinkError(open_failure(path, ec));
}

void SerialStream::Impl::configure() {
  using base = asio::serial_port_base;
  error_code ec;
  port.set_option(base::baud_rate(options.baud), ec);
  if (ec)
    throw LinkError("cannot set " + std::to_string(options.baud) + " baud on " + path + ": " + ec.message() +
                    " (setup mode needs 115200)");
  const auto set = [&](const auto& option, const char* what) {
    port.set_option(option, ec);
    if (ec) throw LinkError(std::string("cannot set ") + what + " on " + path + ": " + ec.message());
  };
  set(base::character_size(8), "8 data bits");
  set(base::parity(base::parity::none), "no parity");
  set(base::stop_bits(base::stop_bits::one), "one stop bit");
  set(base::flow_control(base::flow_control::none), "no flow control");
  // asio's open() made the line raw already; drop whatever arrived before we were ready.
  ::tcflush(fd(), TCIOFLUSH);
}

// One program per 8I20: an advisory lock every i20 process takes, root included (TIOCEXCL
// below does not stop root), so two tools never interleave their commands on one line.
void SerialStream::Impl::lock() {
  if (::flock(fd(), LOCK_EX | LOCK_NB) == 0) return;
  if (errno != EWOULDBLOCK) {
    notes.push_back("advisory lock not available on " + path + ": " + errno_text(errno));
    return;
  }
  const std::string holder = lock_holder(fd());
  throw LinkError(path + " is in use by " + (holder.empty() ? "another program" : holder) +
                  ": only one program may talk to the 8I20 at a time; wait for it to finish, or stop it");
}

void SerialStream::Impl::request_exclusive() {
  if (!options.exclusive) return;
  if (::ioctl(fd(), TIOCEXCL) == 0)
    notes.push_back("exclusive access: other programs cannot open " + path + " while it is in use");
  else
    notes.push_back("exclusive access not available on " + path + ": " + errno_text(errno));
}

// USB adapters hold received bytes until their latency timer runs out (16 ms on FTDI),
// which would cost every reply 16 ms. Both knobs are best effort: record, never fail.
void SerialStream::Impl::request_low_latency() {
  if (!options.low_latency) return;
  serial_struct info{};
  if (::ioctl(fd(), TIOCGSERIAL, &info) != 0) {
    notes.push_back("low-latency mode: not supported by the driver of " + path + " (" + errno_text(errno) +
                    ")");
  } else if (info.flags & ASYNC_LOW_LATENCY) {
    notes.push_back("low-latency mode: already on");
  } else {
    info.flags |= ASYNC_LOW_LATENCY;
    if (::ioctl(fd(), TIOCSSERIAL, &info) == 0)
      notes.push_back("low-latency mode: on (ASYNC_LOW_LATENCY)");
    else
      notes.push_back("low-latency mode: the driver refused ASYNC_LOW_LATENCY (" + errno_text(errno) + ")");
  }
  notes.push_back(tune_usb_latency_timer(options.sysfs_root, tty_name(path)));
}

// Runs the io_context until both the operation and its deadline timer have completed.
// run_for bounds every wait; if asio somehow still has them after the deadline, cancel
// them, and as a last resort close the port so no handler outlives the caller's frame.
void SerialStream::Impl::run_until_done(const bool& op_done, const bool& timer_done,
                                        Clock::time_point deadline) {
  const std::chrono::milliseconds grace = options.cancel_grace;
  const auto give_up = deadline < Clock::time_point::max() - grace ? deadline + grace : deadline;
  io.restart();
  // run_for returns as soon as both handlers ran; slices keep a far deadline from overflowing.
  while (!(op_done && timer_done) && Clock::now() < give_up) io.run_for(std::chrono::seconds(1));
  if (op_done && timer_done) return;
  error_code ignored;
  port.cancel(ignored);
  timer.cancel();
  io.restart();
  io.run_for(grace);
  if (op_done && timer_done) return;
  port.close(ignored);
  io.restart();
  io.run_for(grace);
  throw LinkError("the serial driver of " + path + " stopped responding; unplug and replug the adapter");
}

SerialStream::SerialStream(const std::string& path, Options options)
    : impl_(std::make_unique<Impl>(path, std::move(options))) {
  impl_->open();
  impl_->lock();  // before touching the line settings another program may be using
  impl_->configure();
  impl_->request_exclusive();
  impl_->request_low_latency();
}

SerialStream::~SerialStream() {
  if (impl_ && impl_->port.is_open() && impl_->options.exclusive) ::ioctl(impl_->fd(), TIOCNXCL);
}

void SerialStream::write(lbp::ByteView bytes) {
  if (bytes.empty()) return;
  auto& s = *impl_;
  bool write_done = false;
  bool timer_done = false;
  error_code write_ec;
  asio::async_write(s.port, asio::buffer(bytes.data(), bytes.size()), [&](const error_code& ec, std::size_t) {
    write_done = true;
    write_ec = ec;
    s.timer.cancel();
  });
  const auto wire = std::chrono::microseconds(bytes.size() * 10'000'000ULL / std::max(s.options.baud, 1u));
  s.timer.expires_after(wire + s.options.write_slack.get());
  s.timer.async_wait([&](const error_code& ec) {
    timer_done = true;
    if (!ec) s.port.cancel();
  });
  s.run_until_done(write_done, timer_done, s.timer.expiry());
  if (write_ec == asio::error::operation_aborted)
    throw TimeoutError("writing to " + s.path + " did not finish in time: is the adapter still plugged in?");
  if (write_ec)
    throw LinkError("writing to " + s.path + " failed: " + write_ec.message() + " (adapter unplugged?)");
}

std::size_t SerialStream::read_some(std::span<lbp::Byte> buffer, Clock::time_point deadline) {
  if (buffer.empty()) return 0;
  auto& s = *impl_;
  bool read_done = false;
  bool timer_done = false;
  std::size_t count = 0;
  error_code read_ec;
  // asio tries the read at once, so a deadline already past still returns buffered bytes.
  s.port.async_read_some(asio::buffer(buffer.data(), buffer.size()),
                         [&](const error_code& ec, std::size_t n) {
                           read_done = true;
                           read_ec = ec;
                           count = n;
                           s.timer.cancel();
                         });
  s.timer.expires_at(deadline);
  s.timer.async_wait([&](const error_code& ec) {
    timer_done = true;
    if (!ec) s.port.cancel();
  });
  s.run_until_done(read_done, timer_done, deadline);
  if (!read_ec || read_ec == asio::error::operation_aborted) return count;
  if (read_ec == asio::error::eof || read_ec.value() == EIO)
    throw LinkError(s.path + " was disconnected (USB adapter unplugged?)");
  throw LinkError("reading from " + s.path + " failed: " + read_ec.message());
}

void SerialStream::discard_input() {
  if (::tcflush(impl_->fd(), TCIFLUSH) != 0)
    throw LinkError("cannot discard input on " + impl_->path + ": " + errno_text(errno));
}

unsigned SerialStream::baud() const {
  return impl_->options.baud;
}

std::string SerialStream::name() const {
  return impl_->path;
}

std::vector<std::string> SerialStream::notes() const {
  return impl_->notes;
}

std::string tune_usb_latency_timer(const fs::path& sysfs_root, const std::string& tty_name) {
  const auto file = sysfs_root / "bus/usb-serial/devices" / tty_name / "latency_timer";
  std::error_code ec;
  if (!fs::exists(file, ec))
    return "latency timer: " + tty_name + " is not a usb-serial adapter (no " + file.string() + ")";
  const auto read_value = [&]() -> std::string {
    char text[16] = {};
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return {};
    const auto n = ::read(fd, text, sizeof text - 1);
    ::close(fd);
    std::string value(text, n > 0 ? static_cast<std::size_t>(n) : 0);
    while (!value.empty() && (value.back() == '\n' || value.back() == ' ')) value.pop_back();
    return value;
  };
  const std::string before = read_value();
  if (before == "1") return "latency timer: already 1 ms";
  const int fd = ::open(file.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  int error = fd < 0 ? errno : 0;
  if (fd >= 0) {
    if (::write(fd, "1", 1) != 1) error = errno;
    if (::close(fd) != 0 && error == 0) error = errno;
  }
  if (error == 0 && read_value() == "1") return "latency timer: set to 1 ms (was " + before + " ms)";
  return "latency timer: stays at " + (before.empty() ? std::string("?") : before) + " ms, cannot write " +
         file.string() + " (" + (error ? errno_text(error) : std::string("value did not change")) +
         "); replies will be slower. Fix: a udev rule ACTION==\"add\", SUBSYSTEM==\"usb-serial\", "
         "ATTR{latency_timer}=\"1\"";
}

}  // namespace i20::link
