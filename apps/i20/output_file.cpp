// SPDX-License-Identifier: GPL-2.0-or-later
#include "output_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <system_error>

#include "error/error.hpp"

namespace i20::cli {
namespace fs = std::filesystem;

namespace {

bool writable(const fs::path& p) {
  return ::access(p.c_str(), W_OK) == 0;
}

fs::path folder_of(const fs::path& file) {
  const fs::path parent = file.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

// A temporary file that is removed unless it was moved into place.
class TempFile {
 public:
  // Created with mode 0666 (less the umask), as the final file would be; O_EXCL: never an
  // existing file.
  explicit TempFile(const fs::path& folder) {
    std::random_device random;
    for (int attempt = 0; attempt < 100 && fd_ < 0; ++attempt) {
      path_ = (folder / (".i20-" + std::to_string(::getpid()) + "-" + std::to_string(random()) + ".tmp"))
                  .string();
      fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd_ < 0 && errno != EEXIST) break;
    }
    if (fd_ < 0) {
      const std::string why = std::strerror(errno);
      path_.clear();
      throw Error("cannot write in " + folder.string() + ": " + why, ErrorKind::BadInput);
    }
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!path_.empty()) ::unlink(path_.c_str());
  }
  void write_all(const std::string& text) {
    std::size_t done = 0;
    while (done < text.size()) {
      const auto n = ::write(fd_, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw Error("cannot write " + path_ + ": " + std::strerror(errno));
      done += static_cast<std::size_t>(n);
    }
    if (::fsync(fd_) != 0 || ::close(fd_) != 0) {
      fd_ = -1;
      throw Error("cannot write " + path_ + ": " + std::strerror(errno));
    }
    fd_ = -1;
  }
  const std::string& path() const { return path_; }
  void release() { path_.clear(); }

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace

void write_file_atomically(const std::string& path, const std::string& text, bool overwrite) {
  check_output_file(path, overwrite);
  TempFile temp(folder_of(path));
  temp.write_all(text);
  if (overwrite) {
    if (::rename(temp.path().c_str(), path.c_str()) != 0)
      throw Error("cannot write " + path + ": " + std::strerror(errno));
    temp.release();
    return;
  }
  // link() fails if the name exists: no window in which another file could be replaced.
  if (::link(temp.path().c_str(), path.c_str()) != 0) {
    if (errno == EEXIST)
      throw UsageError(path + " exists; pass --overwrite to replace it (or choose another name)");
    throw Error("cannot write " + path + ": " + std::strerror(errno));
  }
}

void check_output_file(const std::string& path, bool overwrite) {
  if (path.empty() || path == "-") return;
  const fs::path file(path);
  std::error_code ec;
  const auto status = fs::status(file, ec);
  if (fs::is_directory(status)) throw UsageError(path + " is a folder; give a file name");
  if (fs::exists(status)) {
    if (!overwrite)
      throw UsageError(path + " exists; pass --overwrite to replace it (or choose another name)");
    if (!writable(file)) throw UsageError("cannot write " + path + ": permission denied");
    return;
  }
  const fs::path folder = folder_of(file);
  if (!fs::is_directory(folder, ec))
    throw UsageError("cannot write " + path + ": the folder " + folder.string() + " does not exist");
  if (!writable(folder))
    throw UsageError("cannot write " + path + ": the folder " + folder.string() + " is not writable");
}

void check_output_dir(const fs::path& dir) {
  std::error_code ec;
  fs::path existing = dir;
  while (!existing.empty() && !fs::exists(existing, ec)) existing = existing.parent_path();
  if (existing.empty()) existing = ".";
  if (!fs::is_directory(existing, ec))
    throw UsageError("cannot use " + dir.string() + " as a folder: " + existing.string() + " is a file");
  if (!writable(existing))
    throw UsageError("cannot write in " + dir.string() + ": " + existing.string() + " is not writable");
}

}  // namespace i20::cli
