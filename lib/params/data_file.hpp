// SPDX-License-Identifier: GPL-2.0-or-later
// Reading the YAML files users hand the toolkit (parameter overlays, profiles, fault
// tables) with the checks that come before any parsing: a real one is a few KB of text,
// so a wrong path (a directory, a disk image, /dev/zero, a 126 MB log) gets a one-line
// reason instead of a parser building gigabytes from it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <system_error>

namespace i20::params {

// 1 MiB: hundreds of times the largest shipped file, small enough that parsing it stays
// well below 100 MB of memory.
inline constexpr std::uintmax_t kMaxDataFileBytes = std::uintmax_t{1} << 20;

struct DataFileText {
  std::string text;
  std::string problem;  // why the file was refused, without the path; empty when read
};

namespace detail {
inline std::string hex_byte(unsigned char c) {
  constexpr char kDigits[] = "0123456789ABCDEF";
  return std::string("0x") + kDigits[c >> 4] + kDigits[c & 0xF];
}
// YAML is text: tabs and line ends are the only control characters it allows (a NUL
// means a binary file; yaml-cpp would otherwise take it for the end of the text).
inline std::optional<std::size_t> first_control_byte(const std::string& text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') return i;
  }
  return std::nullopt;
}
}  // namespace detail

// The file's text, or the reason it is refused: missing, unreadable, a directory, larger
// than `limit` bytes (checked before reading; pipes and devices are read up to the limit
// only), or not text. `what` names the file in the reason ("profile", "fault table").
inline DataFileText read_data_file(const std::filesystem::path& path, const std::string& what,
                                   std::uintmax_t limit = kMaxDataFileBytes) {
  DataFileText out;
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    out.problem = "cannot open the " + what + " (does it exist and is it readable?)";
    return out;
  }
  if (std::filesystem::is_directory(status)) {
    out.problem = "is a directory, not a " + what;
    return out;
  }
  const auto too_large = [&] {
    return "the " + what + " is larger than " + std::to_string(limit) +
           " bytes, the limit for it (a real one is a few KB)";
  };
  if (std::filesystem::is_regular_file(status)) {
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec && size > limit) {
      out.problem = too_large();
      return out;
    }
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    out.problem = "cannot open the " + what + " (does it exist and is it readable?)";
    return out;
  }
  // Chunks up to one byte past the limit: a pipe or a device has no size to check first.
  std::string text;
  char chunk[16384];
  while (text.size() <= limit && in.read(chunk, sizeof chunk).gcount() > 0)
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
  if (text.size() > limit) {
    out.problem = too_large();
    return out;
  }
  if (in.bad()) {
    out.problem = "cannot read the " + what + " (I/O error)";
    return out;
  }
  if (const auto at = detail::first_control_byte(text)) {
    out.problem = "the " + what + " holds the control byte " +
                  detail::hex_byte(static_cast<unsigned char>(text[*at])) + " at offset " +
                  std::to_string(*at) + ": it is not a YAML text file";
    return out;
  }
  out.text = std::move(text);
  return out;
}

}  // namespace i20::params
