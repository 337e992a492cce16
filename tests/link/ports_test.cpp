// SPDX-License-Identifier: GPL-2.0-or-later
// Port listing against a fake sysfs tree shaped like a real one: class/tty entries are
// symlinks into devices/, "device" links up to the hardware, USB ids live on the USB
// device a few levels up.
#include "link/ports.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <fstream>

using namespace i20::link;
namespace fs = std::filesystem;

namespace {

class FakeSystem {
 public:
  FakeSystem() {
    std::string pattern = (fs::temp_directory_path() / "i20-ports-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    root_ = pattern;
    sys_ = root_ / "sys";
    dev_ = root_ / "dev";
    fs::create_directories(sys_ / "class/tty");
    fs::create_directories(dev_);
  }
  ~FakeSystem() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  PortScanRoots roots() const { return {sys_, dev_}; }
  const fs::path& sys() const { return sys_; }

  // A tty whose hardware is at devices/<hardware>; the class entry lives under
  // devices/<hardware>/tty/<name> (or <tty_dir>/tty/<name> for usb-serial, where the
  // tty's "device" is the port node below the interface).
  void tty(const std::string& name, const std::string& hardware, const std::string& driver) {
    const auto hw = sys_ / "devices" / hardware;
    const auto node = hw / "tty" / name;
    fs::create_directories(node);
    link(node, sys_ / "class/tty" / name);
    link(hw, node / "device");
    fs::create_directories(sys_ / "bus/drivers" / driver);
    link(sys_ / "bus/drivers" / driver, hw / "driver");
    std::ofstream(dev_ / name) << "";
  }
  void subsystem(const std::string& device, const std::string& bus) {
    fs::create_directories(sys_ / "bus" / bus);
    link(sys_ / "bus" / bus, sys_ / "devices" / device / "subsystem");
  }
  void virtual_tty(const std::string& name) {
    const auto node = sys_ / "devices/virtual/tty" / name;
    fs::create_directories(node);
    link(node, sys_ / "class/tty" / name);
  }
  void attribute(const std::string& device, const std::string& name, const std::string& value) {
    std::ofstream(sys_ / "devices" / device / name) << value << "\n";
  }
  void by_id(const std::string& id, const std::string& tty) {
    fs::create_directories(dev_ / "serial/by-id");
    link(dev_ / tty, dev_ / "serial/by-id" / id);
  }
  void usb_device(const std::string& path, const std::string& vid, const std::string& pid,
                  const std::string& maker, const std::string& product, const std::string& serial) {
    fs::create_directories(sys_ / "devices" / path);
    attribute(path, "idVendor", vid);
    attribute(path, "idProduct", pid);
    if (!maker.empty()) attribute(path, "manufacturer", maker);
    if (!product.empty()) attribute(path, "product", product);
    if (!serial.empty()) attribute(path, "serial", serial);
  }

 private:
  // Relative links, as sysfs and udev make them.
  static void link(const fs::path& target, const fs::path& at) {
    fs::create_symlink(fs::relative(target, at.parent_path()), at);
  }

  fs::path root_, sys_, dev_;
};

constexpr const char* kUsb = "pci0000:00/0000:00:14.0/usb1";

// An FTDI adapter (as in Mesa's 3I22) on ttyUSB0.
void add_ftdi(FakeSystem& s, const std::string& tty = "ttyUSB0", const std::string& port = "1-2") {
  const std::string usb = std::string(kUsb) + "/" + port;
  s.usb_device(usb, "0403", "6001", "FTDI", "FT232R USB UART", "A10K1234");
  s.tty(tty, usb + "/" + port + ":1.0/" + tty, "ftdi_sio");
}

const PortInfo* find(const std::vector<PortInfo>& ports, const std::string& name) {
  for (const auto& p : ports)
    if (p.name == name) return &p;
  return nullptr;
}

}  // namespace

TEST(Ports, UsbAdapterCarriesIdsStringsDriverAndById) {
  FakeSystem s;
  add_ftdi(s);
  s.by_id("usb-FTDI_FT232R_USB_UART_A10K1234-if00-port0", "ttyUSB0");
  const auto ports = list_ports(s.roots());
  ASSERT_EQ(ports.size(), 1u);
  const auto& p = ports[0];
  EXPECT_EQ(p.name, "ttyUSB0");
  EXPECT_EQ(p.device, s.roots().dev / "ttyUSB0");
  EXPECT_EQ(p.by_id.filename(), "usb-FTDI_FT232R_USB_UART_A10K1234-if00-port0");
  EXPECT_EQ(p.driver, "ftdi_sio");
  ASSERT_TRUE(p.is_usb());
  EXPECT_EQ(*p.vendor_id, 0x0403);
  EXPECT_EQ(*p.product_id, 0x6001);
  EXPECT_EQ(p.manufacturer, "FTDI");
  EXPECT_EQ(p.product, "FT232R USB UART");
  EXPECT_EQ(p.serial_number, "A10K1234");
  const auto text = p.summary();
  EXPECT_NE(text.find("[0403:6001]"), std::string::npos) << text;
  EXPECT_NE(text.find("FTDI FT232R USB UART"), std::string::npos) << text;
  EXPECT_NE(text.find("A10K1234"), std::string::npos) << text;
}

TEST(Ports, CdcAcmDeviceIsFoundThroughItsInterface) {
  FakeSystem s;
  const std::string usb = std::string(kUsb) + "/1-3";
  s.usb_device(usb, "2341", "0043", "", "", "");  // no strings: they stay empty
  s.tty("ttyACM0", usb + "/1-3:1.0", "cdc_acm");
  const auto ports = list_ports(s.roots());
  ASSERT_EQ(ports.size(), 1u);
  EXPECT_EQ(ports[0].driver, "cdc_acm");
  EXPECT_EQ(ports[0].vendor_id, 0x2341);
  EXPECT_EQ(ports[0].product_id, 0x0043);
  EXPECT_TRUE(ports[0].manufacturer.empty());
  EXPECT_TRUE(ports[0].by_id.empty());
}

TEST(Ports, SkipsVirtualTerminalsAndEmptyUartSlots) {
  FakeSystem s;
  s.virtual_tty("tty0");
  s.virtual_tty("console");
  s.virtual_tty("ptmx");
  s.tty("ttyS0", "pnp0/00:04", "serial");  // a real 16550A
  s.attribute("pnp0/00:04/tty/ttyS0", "type", "4");
  s.tty("ttyS1", "platform/serial8250", "serial8250");  // a slot with no UART
  s.attribute("platform/serial8250/tty/ttyS1", "type", "0");
  add_ftdi(s);
  const auto ports = list_ports(s.roots());
  ASSERT_EQ(ports.size(), 2u);
  EXPECT_NE(find(ports, "ttyS0"), nullptr);
  EXPECT_NE(find(ports, "ttyUSB0"), nullptr);
  EXPECT_EQ(find(ports, "ttyS1"), nullptr);
  EXPECT_EQ(find(ports, "tty0"), nullptr);
  EXPECT_FALSE(find(ports, "ttyS0")->is_usb()) << "a motherboard port has no USB ids";
  EXPECT_EQ(find(ports, "ttyS0")->driver, "serial");
}

TEST(Ports, NamesTheUartDriverBehindSerialBaseDevices) {
  FakeSystem s;  // kernels >= 6.5: pnp device / serial-base ctrl / serial-base port / tty
  s.tty("ttyS0", "pnp0/00:00/00:00:0/00:00:0.0", "port");
  s.subsystem("pnp0/00:00/00:00:0/00:00:0.0", "serial-base");
  s.subsystem("pnp0/00:00/00:00:0", "serial-base");
  fs::create_directories(s.sys() / "bus/drivers/serial");
  fs::create_symlink(fs::relative(s.sys() / "bus/drivers/serial", s.sys() / "devices/pnp0/00:00"),
                     s.sys() / "devices/pnp0/00:00/driver");
  s.attribute("pnp0/00:00/00:00:0/00:00:0.0/tty/ttyS0", "type", "4");
  const auto ports = list_ports(s.roots());
  ASSERT_EQ(ports.size(), 1u);
  EXPECT_EQ(ports[0].driver, "serial");
}

TEST(Ports, SortedTheWayPeopleCount) {
  FakeSystem s;
  add_ftdi(s, "ttyUSB10", "1-4");
  add_ftdi(s, "ttyUSB2", "1-5");
  add_ftdi(s, "ttyUSB0", "1-6");
  const auto ports = list_ports(s.roots());
  ASSERT_EQ(ports.size(), 3u);
  EXPECT_EQ(ports[0].name, "ttyUSB0");
  EXPECT_EQ(ports[1].name, "ttyUSB2");
  EXPECT_EQ(ports[2].name, "ttyUSB10");
}

TEST(Ports, MissingSysfsGivesAnEmptyList) {
  EXPECT_TRUE(list_ports({"/nonexistent-sysfs-for-i20", "/nonexistent-dev"}).empty());
}
