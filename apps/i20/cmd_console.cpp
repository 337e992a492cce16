// SPDX-License-Identifier: GPL-2.0-or-later
// i20 console: the local web console (lib/console serves, console_api.cpp answers through
// lib/ops). It opens the card first, prints the one URL with its token, and serves until
// Ctrl-C, after which the card is settled as after any other command.
#include <CLI/CLI.hpp>
#include <boost/asio/ip/address.hpp>
#include <boost/system/system_error.hpp>
#include <filesystem>
#include <iostream>

#include "browser_open.hpp"
#include "console/server.hpp"
#include "console/static_files.hpp"
#include "console_api.hpp"
#include "context.hpp"
#include "ops/core/session.hpp"
#include "ops/core/timing.hpp"
#include "terminal.hpp"

namespace i20::cli {
namespace {

namespace fs = std::filesystem;

struct ConsoleOptions {
  std::string address = "127.0.0.1";
  unsigned short port = 0;
  unsigned interval_ms = static_cast<unsigned>(ops::timing::kConsoleLiveInterval.count());
  bool no_browser = false;
};

void run_console(Context& ctx, const ConsoleOptions& o) {
  auto& session = ctx.session();
  auto& amp = session.amp();  // a card that does not answer is an error now, not a page later
  std::error_code ec;
  const auto static_dir = console::default_static_dir(fs::read_symlink("/proc/self/exe", ec));
  if (!fs::is_regular_file(static_dir / "index.html", ec)) {
    std::string message = "the console's pages are not installed (no ";
    message += (static_dir / "index.html").string();
    message += ")";
    throw Error(message);
  }
  ConsoleApi api(session, std::chrono::milliseconds(o.interval_ms));
  console::ServerOptions options{.timing = {.live_interval = std::chrono::milliseconds(o.interval_ms),
                                            .stop_poll = ops::timing::kConsoleStopPoll,
                                            .drain = ops::timing::kConsoleDrain,
                                            .idle = ops::timing::kConsoleIdle}};
  options.address = o.address;
  options.port = o.port;
  options.static_dir = static_dir;
  std::unique_ptr<console::Server> server;
  try {
    server = std::make_unique<console::Server>(options, api);
  } catch (const boost::system::system_error& e) {
    std::string message = "cannot listen on ";
    message += console::authority(o.address, o.port);
    message += ": ";
    message += e.code().message();
    throw UsageError(message);
  }
  if (!boost::asio::ip::make_address(o.address).is_loopback())
    std::cerr << "i20: warning: the console is reachable from other hosts on " << o.address
              << " (plain HTTP): whoever learns the token can write to and reset this card\n";
  std::cout << "i20 console for " << amp.describe() << "\n"
            << "  open " << server->url() << "\n"
            << "  (the token in this URL is the only way in; Ctrl-C stops the console and leaves the card "
               "settled)\n"
            << std::flush;
  // The URL carries the only token: a console nobody can reach must not serve (exit 6).
  app::require_stdout();
  BrowserLauncher browser;
  if (!o.no_browser && BrowserLauncher::desktop_present() && !browser.open(server->url()))
    std::cerr << "i20: could not start xdg-open: open the URL above yourself\n";
  server->run([&session] { return session.stop_requested(); });
  ctx.record(session.stop_requested() ? ops::Outcome::Interrupted : ops::Outcome::Done);
}

}  // namespace

void register_console_command(CLI::App& app, Context& ctx) {
  auto options = std::make_shared<ConsoleOptions>();
  auto* console = app.add_subcommand(
      "console",
      "Local web console: overview, parameters (edit, preview, apply), faults, and a live plot of bus "
      "voltage, temperature and FAULT/STATUS, in the browser. Serves on 127.0.0.1 (unless --listen says "
      "otherwise) "
      "and prints one URL with a token for this run; every read and write goes through the same checks as "
      "the commands");
  console
      ->add_option("--listen", options->address,
                   "Address to serve on (default 127.0.0.1). Another address EXPOSES the console, and "
                   "through it the card's writes and reset, to every host that can reach that address and "
                   "learns the token; plain HTTP, no TLS")
      ->capture_default_str();
  console->add_option("--listen-port", options->port, "TCP port (0: a free one)")->capture_default_str();
  console->add_option("--interval", options->interval_ms, "Live sample interval, ms")
      ->check(CLI::Range(20, 10000))
      ->capture_default_str();
  console->add_flag("--no-browser", options->no_browser,
                    "Do not open the page in the desktop's browser (it opens by xdg-open when a desktop "
                    "and a terminal are present; the token goes through a private file, never a command "
                    "line)");
  console->footer("Exit 130 after Ctrl-C (the card settled), 1 card not reached, 2 cannot listen.");
  console->callback([&ctx, options] { run_console(ctx, *options); });
}

}  // namespace i20::cli
