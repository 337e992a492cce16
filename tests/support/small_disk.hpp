// SPDX-License-Identifier: GPL-2.0-or-later
// A folder on a tmpfs of a few KiB, so a write can meet a full disk for real. Needs root
// (CI runs as root); mounted() is false otherwise and the test skips.
#pragma once

#include <sys/mount.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace i20::test {

class SmallDisk {
 public:
  SmallDisk(const std::filesystem::path& where, int kib) : path_(where) {
    std::filesystem::create_directories(path_);
    const std::string options = "size=" + std::to_string(kib) + "k";
    mounted_ = ::mount("tmpfs", path_.c_str(), "tmpfs", 0, options.c_str()) == 0;
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(path_.c_str(), MNT_DETACH);
  }
  SmallDisk(const SmallDisk&) = delete;
  SmallDisk& operator=(const SmallDisk&) = delete;
  bool mounted() const { return mounted_; }
  const std::filesystem::path& path() const { return path_; }
  // Fills the disk up, leaving nothing free.
  void fill() const {
    std::ofstream filler(path_ / "filler", std::ios::binary);
    const std::string block(1024, 'x');
    while (filler.write(block.data(), static_cast<std::streamsize>(block.size()))) {
    }
  }
  void free_space() const { std::filesystem::remove(path_ / "filler"); }

 private:
  std::filesystem::path path_;
  bool mounted_ = false;
};

}  // namespace i20::test
