// SPDX-License-Identifier: GPL-2.0-or-later
#include "pty.hpp"

#include <fcntl.h>
#include <stdlib.h>
#include <termios.h>

#include <cerrno>
#include <cstring>

#include "sim/error.hpp"

namespace i20::sim::app {
namespace {

[[noreturn]] void fail(const std::string& what) {
  throw ConfigError(what + " failed: " + std::strerror(errno) + " (is /dev/ptmx available?)");
}

}  // namespace

Pty::Pty() {
  master_.reset(::posix_openpt(O_RDWR | O_NOCTTY));
  if (!master_) fail("posix_openpt");
  if (::grantpt(master_.get()) != 0) fail("grantpt");
  if (::unlockpt(master_.get()) != 0) fail("unlockpt");
  const char* name = ::ptsname(master_.get());
  if (!name) fail("ptsname");
  slave_path_ = name;
  slave_.reset(::open(name, O_RDWR | O_NOCTTY));
  if (!slave_) fail("open " + slave_path_);
  termios tio{};
  if (::tcgetattr(slave_.get(), &tio) != 0) fail("tcgetattr");
  ::cfmakeraw(&tio);
  ::cfsetispeed(&tio, B115200);
  ::cfsetospeed(&tio, B115200);
  if (::tcsetattr(slave_.get(), TCSANOW, &tio) != 0) fail("tcsetattr");
  const int flags = ::fcntl(master_.get(), F_GETFL);
  if (flags < 0 || ::fcntl(master_.get(), F_SETFL, flags | O_NONBLOCK) != 0) fail("fcntl O_NONBLOCK");
}

}  // namespace i20::sim::app
