// SPDX-License-Identifier: GPL-2.0-or-later
#include "output_file.hpp"

#include <unistd.h>

#include <system_error>

#include "error/error.hpp"
#include "files/atomic_file.hpp"

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

}  // namespace

void write_file_atomically(const std::string& path, const std::string& text, bool overwrite) {
  check_output_file(path, overwrite);
  files::write_file(path, text, overwrite ? files::Existing::Replace : files::Existing::Refuse);
}

void check_output_file(const std::string& path, bool overwrite) {
  if (path.empty() || path == "-") return;
  const fs::path file(path);
  std::error_code ec;
  const auto status = fs::status(file, ec);
  if (fs::is_directory(status)) throw UsageError(path + " is a folder; give a file name");
  // --overwrite replaces a regular file, never a device node (-o /dev/null as root), a FIFO or
  // the link itself. Standard output is "-".
  if (const std::string kind = files::not_a_regular_file(file); !kind.empty())
    throw UsageError(path + " is " + kind +
                     ", not a regular file: only a regular file is written or replaced" +
                     (kind == "a symbolic link" ? " (give the file it points to)"
                                                : " (give a file name, or - for standard output)"));
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
