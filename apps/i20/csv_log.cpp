// SPDX-License-Identifier: GPL-2.0-or-later
#include "csv_log.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "error/error.hpp"
#include "files/atomic_file.hpp"

namespace i20::cli {

namespace {

// The log is written like every other output (output_file.hpp): never into a device node, a
// FIFO, a socket or through a link, and a failed start removes only a regular file of its own.
const std::string& regular_file(const std::string& path) {
  if (const std::string kind = files::not_a_regular_file(path); !kind.empty())
    throw UsageError("cannot write the log file " + path + ": it is " + kind +
                     ", not a regular file (give a file name)");
  return path;
}

}  // namespace

CsvLog::CsvLog(const std::string& path, const std::string& header)
    : path_(path), out_(regular_file(path), std::ios::out | std::ios::trunc) {
  if (!out_) throw UsageError("cannot write the log file " + path + ": check the directory exists");
  errno = 0;
  out_ << header;
  out_.flush();
  if (!out_) {  // not even the header landed: no file is better than an empty one
    const std::string why = errno != 0 ? std::strerror(errno) : "a write failed";
    out_.close();
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    throw OutputError("cannot write the log file " + path + ": " + why + "; no log was written");
  }
}

void CsvLog::write(const std::string& rows) {
  errno = 0;
  out_ << rows;
  out_.flush();
  if (!out_)
    throw OutputError("cannot write the log file " + path_ + ": " +
                      (errno != 0 ? std::strerror(errno) : "a write failed") +
                      "; it holds the rows written before");
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace i20::cli
