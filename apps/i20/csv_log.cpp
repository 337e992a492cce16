// SPDX-License-Identifier: GPL-2.0-or-later
#include "csv_log.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "error/error.hpp"

namespace i20::cli {

CsvLog::CsvLog(const std::string& path, const std::string& header)
    : path_(path), out_(path, std::ios::out | std::ios::trunc) {
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
