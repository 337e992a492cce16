// SPDX-License-Identifier: GPL-2.0-or-later
#include "console/static_files.hpp"

#include <array>
#include <utility>

#include "console/console_paths.hpp"

namespace i20::console {
namespace fs = std::filesystem;
namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// The only files the pages are made of.
const char* content_type_of(const fs::path& file) {
  static constexpr std::array<std::pair<const char*, const char*>, 6> kTypes{{
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".ico", "image/x-icon"},
  }};
  const auto ext = file.extension().string();
  for (const auto& [e, type] : kTypes)
    if (ext == e) return type;
  return nullptr;
}

// Every segment a plain file name: no "." or "..", no backslash or NUL, no hidden files.
bool safe_segments(const std::string& path) {
  std::size_t start = 1;
  while (start <= path.size()) {
    const auto end = std::min(path.find('/', start), path.size());
    const std::string segment = path.substr(start, end - start);
    if (segment == "." || segment == ".." || (!segment.empty() && segment.front() == '.')) return false;
    if (segment.find_first_of(std::string("\\\0:", 3)) != std::string::npos) return false;
    start = end + 1;
  }
  return true;
}

}  // namespace

std::optional<std::string> percent_decode(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      out += text[i];
      continue;
    }
    if (i + 2 >= text.size()) return std::nullopt;
    const int hi = hex_digit(text[i + 1]);
    const int lo = hex_digit(text[i + 2]);
    if (hi < 0 || lo < 0) return std::nullopt;
    out += static_cast<char>(hi * 16 + lo);
    i += 2;
  }
  return out;
}

StaticLookup find_static(const fs::path& root, const std::string& url_path, StaticFile& out) {
  const auto decoded = percent_decode(url_path);
  if (!decoded || decoded->empty() || decoded->front() != '/' || !safe_segments(*decoded))
    return StaticLookup::Forbidden;
  const std::string relative = *decoded == "/" ? "index.html" : decoded->substr(1);
  const auto* type = content_type_of(relative);
  if (type == nullptr) return StaticLookup::Forbidden;
  std::error_code ec;
  const auto base = fs::canonical(root, ec);
  if (ec) return StaticLookup::NotFound;
  const auto file = fs::weakly_canonical(base / relative, ec);
  if (ec) return StaticLookup::NotFound;
  // A symbolic link inside the folder must not lead out of it either.
  const auto rel = file.lexically_relative(base);
  if (rel.empty() || *rel.begin() == "..") return StaticLookup::Forbidden;
  if (!fs::is_regular_file(file, ec)) return StaticLookup::NotFound;
  out = {file, type};
  return StaticLookup::Found;
}

fs::path default_static_dir(const fs::path& exe) {
  if (!exe.empty() && exe.parent_path() == fs::path(std::string(paths::kBuildBinDir)))
    return fs::path(std::string(paths::kSourceDir));
  // PREFIX/bin/i20 -> PREFIX/share/i20tools/console, so a moved tree still finds its pages.
  if (!exe.empty()) {
    const auto relocated = exe.parent_path().parent_path() / std::string(paths::kInstallRelative);
    std::error_code ec;
    if (fs::is_directory(relocated, ec)) return relocated;
  }
  return fs::path(std::string(paths::kInstallDir));
}

}  // namespace i20::console
