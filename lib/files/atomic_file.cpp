// SPDX-License-Identifier: GPL-2.0-or-later
#include "files/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <random>

#include "error/error.hpp"

namespace i20::files {
namespace fs = std::filesystem;

namespace {

std::string reason(int error) {
  return std::strerror(error);
}

fs::path folder_of(const fs::path& file) {
  const fs::path parent = file.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

// A descriptor closed on every path out, so a failure never leaks one.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  // Closes now and says whether the close succeeded (NFS reports write errors here).
  bool close() {
    const int fd = fd_;
    fd_ = -1;
    return ::close(fd) == 0;
  }

 private:
  int fd_;
};

// The hidden temporary file, removed unless it was given its name.
class TemporaryFile {
 public:
  // Mode 0666 less the umask, as the final file would get from open(2); O_EXCL: never an
  // existing file. (mkstemp would make it 0600, and a saved profile unreadable to others.)
  TemporaryFile(const fs::path& folder, const std::string& for_name) {
    std::random_device random;
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
      path_ = folder /
              ("." + for_name + "." + std::to_string(::getpid()) + "-" + std::to_string(random()) + ".tmp");
      fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd < 0 && errno != EEXIST) break;
    }
    if (fd < 0)
      throw OutputError("cannot write " + (folder / for_name).string() + ": cannot create a file in " +
                        folder.string() + ": " + reason(errno));
    fd_ = std::make_unique<Fd>(fd);
  }
  ~TemporaryFile() {
    if (!kept_) ::unlink(path_.c_str());
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;

  // Every byte written, flushed to disk and closed; throws OutputError naming `shown`.
  void fill(std::string_view text, const fs::path& shown) {
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(fd_->get(), text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw OutputError("cannot write " + shown.string() + ": " + reason(n < 0 ? errno : ENOSPC));
      done += static_cast<std::size_t>(n);
    }
    if (::fsync(fd_->get()) != 0) throw OutputError("cannot write " + shown.string() + ": " + reason(errno));
    if (!fd_->close()) throw OutputError("cannot write " + shown.string() + ": " + reason(errno));
  }
  const fs::path& path() const { return path_; }
  void keep() { kept_ = true; }

 private:
  std::unique_ptr<Fd> fd_;
  fs::path path_;
  bool kept_ = false;
};

// The new name in the folder survives a power loss only once the folder is flushed too.
void sync_folder(const fs::path& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;  // the file is in place; a folder that cannot be opened cannot be synced
  ::fsync(fd);
  ::close(fd);
}

// Gives the temporary file `name`. Refuse: link(2) fails on an existing name instead of
// replacing it, so a file that appears meanwhile is never overwritten. False on EEXIST.
bool give_name(TemporaryFile& temp, const fs::path& name, Existing existing) {
  if (existing == Existing::Replace) {
    // Checked again here, just before the rename: check_output_file ran before the card was read.
    if (const std::string kind = not_a_regular_file(name); !kind.empty())
      throw OutputError("cannot write " + name.string() + ": it is " + kind +
                        ", not a regular file; nothing was replaced");
    if (::rename(temp.path().c_str(), name.c_str()) != 0)
      throw OutputError("cannot write " + name.string() + ": " + reason(errno));
    temp.keep();
    return true;
  }
  if (::link(temp.path().c_str(), name.c_str()) != 0) {
    if (errno == EEXIST) return false;
    throw OutputError("cannot write " + name.string() + ": " + reason(errno));
  }
  return true;  // the temporary name goes with `temp`
}

}  // namespace

std::string not_a_regular_file(const fs::path& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return "";  // nothing there (or unreadable: the write will say)
  if (S_ISREG(st.st_mode)) return "";
  if (S_ISDIR(st.st_mode)) return "a folder";
  if (S_ISLNK(st.st_mode)) return "a symbolic link";
  if (S_ISCHR(st.st_mode)) return "a character device";
  if (S_ISBLK(st.st_mode)) return "a block device";
  if (S_ISFIFO(st.st_mode)) return "a FIFO";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "a special file";
}

void write_file(const fs::path& path, std::string_view text, Existing existing) {
  const fs::path folder = folder_of(path);
  TemporaryFile temp(folder, path.filename().string());
  temp.fill(text, path);
  if (!give_name(temp, path, existing))
    throw OutputError("cannot write " + path.string() + ": it exists (it appeared while writing)");
  sync_folder(folder);
}

fs::path write_new_file(const fs::path& dir, const std::string& stem, const std::string& extension,
                        std::string_view text) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw OutputError("cannot create the folder " + dir.string() + ": " + ec.message());
  TemporaryFile temp(dir, stem + extension);
  temp.fill(text, dir / (stem + extension));
  for (int n = 1; n < 1000; ++n) {
    std::string name = stem;  // appended apart: GCC 12's -O3 -Wrestrict misfires on `"-" + std::to_string(n)`
    if (n > 1) {
      name += '-';
      name += std::to_string(n);
    }
    const fs::path path = dir / (name + extension);
    if (give_name(temp, path, Existing::Refuse)) {
      sync_folder(dir);
      return path;
    }
  }
  throw OutputError("cannot find a free name for " + stem + extension + " in " + dir.string());
}

}  // namespace i20::files
