// SPDX-License-Identifier: GPL-2.0-or-later
// Files the toolkit writes are whole or absent: the text goes to a hidden temporary file in
// the destination's folder, is flushed to disk (fsync), and only then takes its name (a
// rename, or a link that refuses an existing name). A full disk, a folder that vanished or a
// signal half way leaves no partial file under the name a user or `profile undo --last`
// would trust. Failures throw OutputError (exit 6) naming the file and the system's reason.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace i20::files {

enum class Existing {
  Refuse,   // an existing file keeps its name and content: OutputError
  Replace,  // an existing file is replaced in one step (readers see the old or the new text)
};

// "a character device", "a FIFO", "a socket", "a block device", "a symbolic link", "a folder"
// for what stands at `path` when it is not a regular file (the link itself, not what it
// points to); "" for a regular file or nothing. Replace never replaces such a thing: renaming
// over /dev/null would destroy the device node, over a link the link.
std::string not_a_regular_file(const std::filesystem::path& path);

// Writes `text` to `path` as described above. Replace replaces a regular file only.
void write_file(const std::filesystem::path& path, std::string_view text, Existing existing);

// Writes `text` to the first free name of `dir`/`stem`.yaml, `stem`-2.yaml, ... (never
// replacing a file, even one that appears meanwhile) and returns it. Creates `dir`.
std::filesystem::path write_new_file(const std::filesystem::path& dir, const std::string& stem,
                                     const std::string& extension, std::string_view text);

}  // namespace i20::files
