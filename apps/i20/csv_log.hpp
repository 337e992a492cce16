// SPDX-License-Identifier: GPL-2.0-or-later
// The CSV file `watch --log` writes (and `watch --passive --log`): a live series, flushed
// row by row so a watch ended by Ctrl-C or a crash keeps every row written so far. A row
// that does not land (a full disk) ends the watch with OutputError (exit 6); the file then
// holds the rows before it, each of them true.
#pragma once

#include <fstream>
#include <string>

namespace i20::cli {

class CsvLog {
 public:
  // Throws UsageError (nothing sent yet) when the file cannot be created.
  CsvLog(const std::string& path, const std::string& header);
  // Appends `rows` (each ending in '\n') and flushes them; throws OutputError on failure.
  void write(const std::string& rows);

 private:
  std::string path_;
  std::ofstream out_;
};

// A CSV field, quoted when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& s);

}  // namespace i20::cli
