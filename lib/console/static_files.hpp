// SPDX-License-Identifier: GPL-2.0-or-later
// The console's pages, served only from its own folder: a request path is decoded once and
// refused when any segment would leave the folder ("..", "%2e%2e", a backslash, a NUL), and
// only the file types the pages use are served.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace i20::console {

// "/a%20b" -> "/a b"; nullopt for a malformed escape.
std::optional<std::string> percent_decode(const std::string& text);

struct StaticFile {
  std::filesystem::path path;
  std::string content_type;
};

enum class StaticLookup { Found, NotFound, Forbidden };

// Resolves a URL path ("/" is index.html) under `root`. Forbidden: the path tries to leave
// the folder or names a file type the console does not serve.
StaticLookup find_static(const std::filesystem::path& root, const std::string& url_path, StaticFile& out);

// The installed pages for a program at `exe` (its /proc/self/exe): the source tree's for a
// build-tree program, PREFIX/share/i20tools/console otherwise.
std::filesystem::path default_static_dir(const std::filesystem::path& exe);

}  // namespace i20::console
