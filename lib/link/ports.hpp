// SPDX-License-Identifier: GPL-2.0-or-later
// Serial ports on Linux, from sysfs: which tty devices have real hardware behind them,
// and for USB adapters (such as Mesa's 3I22) who made them. Helps a user pick the path
// to pass to open_serial_link().
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace i20::link {

struct PortInfo {
  std::string name;              // "ttyUSB0"
  std::filesystem::path device;  // "/dev/ttyUSB0"
  std::filesystem::path by_id;   // "/dev/serial/by-id/usb-FTDI_..." (stable across replugs), or empty
  std::string driver;            // "ftdi_sio", "cdc_acm", "serial", ... (empty if unknown)
  std::optional<std::uint16_t> vendor_id;  // USB only
  std::optional<std::uint16_t> product_id;
  std::string manufacturer;  // USB strings, empty when the device has none
  std::string product;
  std::string serial_number;

  bool is_usb() const { return vendor_id.has_value(); }
  // "/dev/ttyUSB0  FTDI FT232R USB UART [0403:6001] serial A10K1234, driver ftdi_sio"
  std::string summary() const;
};

struct PortScanRoots {
  std::filesystem::path sysfs = "/sys";
  std::filesystem::path dev = "/dev";
};

// Ports in natural order (ttyS2 before ttyS10). Virtual terminals, pseudo-terminals and
// ttyS ports with no UART behind them are left out. Never throws for missing or
// unreadable sysfs entries: what cannot be read stays empty.
std::vector<PortInfo> list_ports(const PortScanRoots& roots = {});

// Other processes that have `device` open ("cat (PID 1234)"), as far as /proc shows them
// (another user's processes are not visible to an unprivileged user). Empty for a path that
// is no device file.
std::vector<std::string> other_programs_with(const std::string& device,
                                             const std::string& proc_root = "/proc");

}  // namespace i20::link
