// SPDX-License-Identifier: GPL-2.0-or-later
#include "control_fifo.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

#include "sim/error.hpp"

namespace i20::sim::app {

ControlFifo::ControlFifo(const std::string& path) : path_(path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (!S_ISFIFO(st.st_mode))
      throw ConfigError(path + " exists and is not a FIFO: choose another --control path");
  } else if (::mkfifo(path.c_str(), 0600) != 0) {
    throw ConfigError("cannot create FIFO " + path + ": " + std::strerror(errno));
  } else {
    created_ = true;
  }
  read_.reset(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  keep_open_.reset(::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC));
  if (!read_ || !keep_open_) throw ConfigError("cannot open FIFO " + path + ": " + std::strerror(errno));
}

ControlFifo::~ControlFifo() {
  if (created_) ::unlink(path_.c_str());
}

std::vector<std::string> LineSplitter::read_from(int fd, bool& eof) {
  std::array<char, 512> buf;
  std::vector<std::string> lines;
  const ssize_t n = ::read(fd, buf.data(), buf.size());
  eof = n == 0;
  for (ssize_t i = 0; i < n; ++i) {
    if (buf[i] != '\n') {
      pending_ += buf[i];
      continue;
    }
    if (!pending_.empty() && pending_.back() == '\r') pending_.pop_back();
    lines.push_back(std::move(pending_));
    pending_.clear();
  }
  return lines;
}

}  // namespace i20::sim::app
