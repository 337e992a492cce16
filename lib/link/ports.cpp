// SPDX-License-Identifier: GPL-2.0-or-later
#include "link/ports.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace i20::link {
namespace fs = std::filesystem;

namespace {

// Walking up from a tty to its USB device takes a handful of steps; a bound keeps a
// strange tree from looping.
constexpr int kMaxParents = 16;

std::string read_attribute(const fs::path& file) {
  std::ifstream in(file);
  std::string value;
  if (!in || !std::getline(in, value)) return {};
  while (!value.empty() && (value.back() == '\r' || value.back() == ' ' || value.back() == '\t'))
    value.pop_back();
  return value;
}

std::optional<std::uint16_t> read_hex_id(const fs::path& file) {
  const auto text = read_attribute(file);
  if (text.empty() || text.size() > 4) return std::nullopt;
  std::uint16_t value = 0;
  for (char ch : text) {
    const int digit = (ch >= '0' && ch <= '9')   ? ch - '0'
                      : (ch >= 'a' && ch <= 'f') ? ch - 'a' + 10
                      : (ch >= 'A' && ch <= 'F') ? ch - 'A' + 10
                                                 : -1;
    if (digit < 0) return std::nullopt;
    value = static_cast<std::uint16_t>(value * 16 + digit);
  }
  return value;
}

fs::path resolve(const fs::path& p) {
  std::error_code ec;
  auto r = fs::canonical(p, ec);
  return ec ? fs::path{} : r;
}

bool is_within(const fs::path& p, const fs::path& root) {
  const auto [r, _] = std::mismatch(root.begin(), root.end(), p.begin(), p.end());
  return r == root.end();
}

// serial_core exposes the UART type; 0 (PORT_UNKNOWN) means the ttyS slot is empty.
bool empty_uart_slot(const fs::path& class_entry) {
  std::error_code ec;
  const auto type = class_entry / "type";
  return fs::exists(type, ec) && read_attribute(type) == "0";
}

// The USB device is the first ancestor of the tty's device that has idVendor.
void fill_usb(PortInfo& port, const fs::path& device, const fs::path& devices_root) {
  fs::path p = device;
  for (int i = 0; i < kMaxParents && is_within(p, devices_root) && p != devices_root;
       ++i, p = p.parent_path()) {
    std::error_code ec;
    if (!fs::exists(p / "idVendor", ec)) continue;
    port.vendor_id = read_hex_id(p / "idVendor");
    port.product_id = read_hex_id(p / "idProduct");
    port.manufacturer = read_attribute(p / "manufacturer");
    port.product = read_attribute(p / "product");
    port.serial_number = read_attribute(p / "serial");
    return;
  }
}

// Kernels since 6.5 put serial-base "ctrl" and "port" devices between a UART's tty and
// its hardware; the driver worth naming is the hardware's ("serial", "ftdi_sio").
std::string driver_of(fs::path device, const fs::path& devices_root) {
  for (int i = 0; i < kMaxParents && is_within(device, devices_root); ++i, device = device.parent_path())
    if (resolve(device / "subsystem").filename() != "serial-base")
      return resolve(device / "driver").filename().string();
  return {};
}

// /dev/serial/by-id names survive replugging and renumbering: worth showing.
fs::path find_by_id(const fs::path& dev_root, const fs::path& device) {
  const auto target = resolve(device);
  if (target.empty()) return {};
  std::error_code ec;
  for (fs::directory_iterator it(dev_root / "serial/by-id", ec), end; !ec && it != end; it.increment(ec))
    if (resolve(it->path()) == target) return it->path();
  return {};
}

std::optional<PortInfo> describe_tty(const fs::directory_entry& entry, const PortScanRoots& roots,
                                     const fs::path& devices_root) {
  const auto device = resolve(entry.path() / "device");
  if (device.empty()) return std::nullopt;  // virtual: consoles, ptys, ptmx
  if (empty_uart_slot(entry.path())) return std::nullopt;
  PortInfo port;
  port.name = entry.path().filename().string();
  port.device = roots.dev / port.name;
  port.driver = driver_of(device, devices_root);
  fill_usb(port, device, devices_root);
  port.by_id = find_by_id(roots.dev, port.device);
  return port;
}

// "ttyUSB10" -> ("ttyUSB", 10), so ports sort the way people count.
std::pair<std::string, long> sort_key(const std::string& name) {
  auto digits = name.find_last_not_of("0123456789") + 1;
  if (digits >= name.size() || name.size() - digits > 9) return {name, -1};
  return {name.substr(0, digits), std::stol(name.substr(digits))};
}

std::string hex4(std::uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof text, "%04x", value);
  return text;
}

}  // namespace

std::string PortInfo::summary() const {
  std::string text = device.string();
  std::string what = manufacturer;
  if (!product.empty()) what += (what.empty() ? "" : " ") + product;
  if (!what.empty()) text += "  " + what;
  if (vendor_id && product_id) text += " [" + hex4(*vendor_id) + ":" + hex4(*product_id) + "]";
  if (!serial_number.empty()) text += " serial " + serial_number;
  if (!driver.empty()) text += ", driver " + driver;
  if (!by_id.empty()) text += ", " + by_id.string();
  return text;
}

std::vector<PortInfo> list_ports(const PortScanRoots& roots) {
  std::vector<PortInfo> ports;
  const auto devices_root = resolve(roots.sysfs / "devices");
  std::error_code ec;
  for (fs::directory_iterator it(roots.sysfs / "class/tty", ec), end; !ec && it != end; it.increment(ec))
    if (auto port = describe_tty(*it, roots, devices_root)) ports.push_back(std::move(*port));
  std::sort(ports.begin(), ports.end(),
            [](const PortInfo& a, const PortInfo& b) { return sort_key(a.name) < sort_key(b.name); });
  return ports;
}

namespace {

std::string trimmed(std::string s) {
  const auto first = s.find_first_not_of(" \t");
  const auto last = s.find_last_not_of(" \t\r\n");
  return first == std::string::npos ? std::string() : s.substr(first, last - first + 1);
}

// For a pty's slave (/dev/pts/N), the process holding its master is the far end (a
// simulator, a terminal), not a second reader: it owns a /dev/ptmx descriptor whose fdinfo
// says tty-index N (or, on kernels that do not say, any /dev/ptmx: then it is not blamed).
bool holds_master_of(const std::filesystem::path& process, const std::string& pty_index) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (const auto& fd : fs::directory_iterator(process / "fd", ec)) {
    std::error_code link_ec;
    const auto target = fs::read_symlink(fd.path(), link_ec).string();
    if (target != "/dev/ptmx" && target != "/dev/pts/ptmx") continue;
    std::ifstream info(process / "fdinfo" / fd.path().filename());
    std::string line;
    bool said = false;
    while (std::getline(info, line))
      if (line.rfind("tty-index:", 0) == 0) {
        said = true;
        if (trimmed(line.substr(10)) == pty_index) return true;
      }
    if (!said) return true;
  }
  return false;
}

}  // namespace

std::vector<std::string> other_programs_with(const std::string& device, const std::string& proc_root) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto target = fs::canonical(device, ec);
  if (ec || !fs::is_character_file(target, ec)) return {};
  const std::string self = std::to_string(::getpid());
  const std::string pts = "/dev/pts/";
  const std::string pty_index = target.string().rfind(pts, 0) == 0 ? target.string().substr(pts.size()) : "";
  std::vector<std::string> found;
  for (const auto& process : fs::directory_iterator(proc_root, ec)) {
    const std::string pid = process.path().filename().string();
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos || pid == self) continue;
    std::error_code fd_ec;
    for (const auto& fd : fs::directory_iterator(process.path() / "fd", fd_ec)) {
      std::error_code link_ec;
      if (fs::read_symlink(fd.path(), link_ec) != target) continue;
      if (!pty_index.empty() && holds_master_of(process.path(), pty_index)) break;
      std::ifstream comm(process.path() / "comm");
      std::string name;
      std::getline(comm, name);
      found.push_back((name.empty() ? std::string("a program") : name) + " (PID " + pid + ")");
      break;
    }
  }
  return found;
}

}  // namespace i20::link
