// SPDX-License-Identifier: GPL-2.0-or-later
// Output files a command writes after talking to a card (report -o, profile save, export
// -o, discover -o, watch --log, tune -o, the apply backup folder) are checked before the
// first byte is sent: a refusal that needs no card must not cost a reset, a RAM scan or a
// read of every parameter.
#pragma once

#include <filesystem>
#include <string>

namespace i20::cli {

// Throws UsageError (exit 2, nothing sent) when `path` cannot become this command's output:
// it exists and `overwrite` is not given, it is a folder, a device, a FIFO, a socket or a
// symbolic link (never replaced, --overwrite or not), its folder does not exist, or the
// folder (or the file) is not writable. "" and "-" (stdout) are always fine.
void check_output_file(const std::string& path, bool overwrite);

// The same for a folder the command creates if missing (the backup folder): it must be a
// folder, or be creatable under the nearest folder that exists and is writable.
void check_output_dir(const std::filesystem::path& dir);

// Writes `text` to `path` so that nobody ever sees half a file (lib/files: a temporary file
// in the same folder, synced, then moved into place): UsageError (exit 2) for an existing
// file without `overwrite`, OutputError (exit 6) when the text does not land; an existing
// file created after check_output_file ran is left alone.
void write_file_atomically(const std::string& path, const std::string& text, bool overwrite);

}  // namespace i20::cli
