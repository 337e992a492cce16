// SPDX-License-Identifier: GPL-2.0-or-later
// Opening the console in the user's browser, where a desktop is present. The URL carries
// the console's token, and a command line is readable by every user of the machine
// (/proc/PID/cmdline): so the browser is handed a private file (0600, in a 0700 folder)
// that redirects to the URL, as Jupyter does, never the URL itself.
#pragma once

#include <filesystem>
#include <string>

namespace i20::cli {

class BrowserLauncher {
 public:
  BrowserLauncher() = default;
  ~BrowserLauncher();  // removes the redirect file
  BrowserLauncher(const BrowserLauncher&) = delete;
  BrowserLauncher& operator=(const BrowserLauncher&) = delete;

  // Whether a browser can be opened here: a desktop session (DISPLAY or WAYLAND_DISPLAY),
  // a terminal on standard output (not a script or a test), and xdg-open on the PATH.
  static bool desktop_present();

  // Starts xdg-open on the redirect file. Returns false (and the caller prints the URL
  // alone, as it always does) when that could not be started.
  bool open(const std::string& url);

 private:
  std::filesystem::path dir_;
};

}  // namespace i20::cli
