// SPDX-License-Identifier: GPL-2.0-or-later
// docs/facts.md s2 (NV access through 0xEC, NV addresses) and s7 (EEPROM write time),
// manual "DRIVE PARAMETER SETUP" (NV values take effect only after a reset).
#include <filesystem>
#include <fstream>

#include "bench.hpp"
#include "sim/error.hpp"

namespace i20::sim::test {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) {
  const auto path = fs::temp_directory_path() / ("i20sim-test-" + std::to_string(::getpid()) + "-" + name);
  fs::remove(path);
  return path;
}

lbp::Bytes file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return lbp::Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(SimNv, ModeOneRoutesDataAccessesToTheEeprom) {
  Bench b;
  b.card.amplifier().write_ram(2, lbp::Bytes{0x77, 0x66});
  EXPECT_EQ(b.send("45 02 00"), reply("77 66")) << "RAM mode: RAM at address 2";
  b.send("EC 01");
  EXPECT_EQ(b.send("45 02 00"), reply("E8 03")) << "NVMAXCURRENT default 1000";
  EXPECT_EQ(b.read(40), 36000u) << "NVBRAKEONV";
  EXPECT_EQ(b.read(42), 34000u) << "NVBRAKEOFFV";
  EXPECT_EQ(b.read(12, 4), 150000u) << "NVKQI";
  EXPECT_EQ(b.read(38), 38500u) << "NVBUSOVERV";
  EXPECT_EQ(b.read(6), 9u) << "NVBAUDRATE 2.5 MBaud";
  b.send("EC 00");
  EXPECT_EQ(b.send("45 02 00"), reply("77 66"));
}

TEST(SimNv, WorkingTwinsStartFromNvValues) {
  Bench b;
  EXPECT_EQ(b.read("MAXCURRENT"), 1000u);
  EXPECT_EQ(b.read("BRAKEONV"), 36000u);
  EXPECT_EQ(b.read("KQI"), 150000u);
  EXPECT_EQ(b.read("KDP"), 50u);
  EXPECT_EQ(b.read("BUSUNDERV"), 3500u);
}

TEST(SimNv, EepromWriteIsAnsweredOnlyWhenTheCellsAreWritten) {
  Bench b;  // 2 ms per 16-bit word
  b.send("EC 01");
  EXPECT_TRUE(b.write16(2, 2000).empty()) << "busy writing";
  EXPECT_TRUE(b.card.eeprom_busy());
  EXPECT_TRUE(b.wait(1ms).empty());
  EXPECT_EQ(b.wait(1ms), lbp::Bytes{0x00});
  EXPECT_FALSE(b.card.eeprom_busy());
  EXPECT_EQ(b.read(2), 2000u);
}

TEST(SimNv, BusyTimeGrowsWithTheWordsWritten) {
  Bench b;
  b.send("EC 01");
  EXPECT_TRUE(b.send("66 0C 00 00 00 01 00").empty());  // NVKQI, 2 words: 4 ms
  EXPECT_TRUE(b.wait(3500us).empty());
  EXPECT_EQ(b.wait(500us), lbp::Bytes{0x00});
  EXPECT_TRUE(b.send("64 03 00 12").empty());  // one byte still costs one word
  EXPECT_EQ(b.wait(2ms), lbp::Bytes{0x00});
}

TEST(SimNv, InputQueuesWhileTheEepromIsBusy) {
  Bench b;
  b.send("EC 01");
  const auto out = b.raw(cat({framed("65 28 00 10 27"), framed("DF"), framed("45 28 00")}));
  EXPECT_TRUE(out.empty()) << "nothing is executed while the EEPROM writes";
  EXPECT_EQ(b.card.rx_pending(), 6u);
  EXPECT_EQ(b.wait(2ms), cat({lbp::Bytes{0x00}, reply("5A"), reply("10 27")}));
}

TEST(SimNv, FloodingDuringAnEepromWriteOverflowsTheBuffer) {
  DeviceOptions o;
  o.rx_buffer_bytes = 32;
  Bench b(o);
  b.send("EC 01");
  lbp::Bytes flood = framed("65 02 00 D0 07");
  for (int i = 0; i < 30; ++i) flood = cat({flood, framed("DF")});  // 60 more bytes
  EXPECT_TRUE(b.raw(flood).empty());
  const auto out = b.wait(2ms);
  EXPECT_EQ(out.size(), 1u + 2 * 16) << "the write's 0x00 and the 16 cookies that fit";
  EXPECT_TRUE(b.local(0xC1) & lbp::local::kStatusBufferOverflow);
}

TEST(SimNv, NvWritesChangeNothingLiveUntilReset) {
  Bench b;
  b.send("EC 01");
  b.write16(2, 2500);
  b.wait(2ms);
  b.send("EC 00");
  EXPECT_EQ(b.read("MAXCURRENT"), 1000u);
  b.write16(b.address_of("MAXCURRENT"), 1700);  // live change, lost at reset
  EXPECT_EQ(b.read("MAXCURRENT"), 1700u);
  b.send("FE 5A");
  b.wait(2ms);
  EXPECT_EQ(b.read("MAXCURRENT"), 2500u) << "reset copies NV into the working twin";
}

TEST(SimNv, FlashAndOutOfRangeEepromWritesAreRefused) {
  Bench b;
  b.send("EC 02");
  EXPECT_EQ(b.send("45 02 00"), reply("FF FF")) << "flash reads as erased";
  EXPECT_EQ(b.write16(2, 1), lbp::Bytes{0x00});
  EXPECT_TRUE(b.local(0xC1) & lbp::local::kStatusInvalidWrite);
  b.send("E1 00");
  b.send("EC 01");
  EXPECT_EQ(b.write16(300, 1), lbp::Bytes{0x00}) << "past the 256-byte EEPROM: refused, answered at once";
  EXPECT_TRUE(b.local(0xC1) & lbp::local::kStatusInvalidWrite);
  EXPECT_EQ(b.card.stats().eeprom_writes, 0u);
}

TEST(SimNv, EepromFileIsCreatedWithDefaultsAndPersists) {
  const auto path = temp_file("persist.eeprom");
  DeviceOptions o;
  o.eeprom_file = path;
  {
    Bench first(o);
    ASSERT_TRUE(fs::exists(path));
    const auto image = file_bytes(path);
    ASSERT_EQ(image.size(), kDefaultEepromBytes);
    EXPECT_EQ(image[40], 0xA0);  // NVBRAKEONV 36000 = 0x8CA0
    EXPECT_EQ(image[41], 0x8C);
    first.send("EC 01");
    first.write16(40, 30000);
    EXPECT_EQ(file_bytes(path)[40], 0xA0) << "not written before the cell write completes";
    first.wait(2ms);
    EXPECT_EQ(file_bytes(path)[40], 30000 & 0xFF) << "written through at completion";
  }
  Bench second(o);
  EXPECT_EQ(second.read("BRAKEONV"), 30000u) << "power-up loads the NV value from the file";
  second.send("EC 01");
  EXPECT_EQ(second.read(40), 30000u);
  fs::remove(path);
}

TEST(SimNv, WrongSizedEepromFileIsRejected) {
  const auto path = temp_file("short.eeprom");
  std::ofstream(path) << "short";
  DeviceOptions o;
  o.eeprom_file = path;
  EXPECT_THROW(Virtual8i20 card(o), ConfigError);
  fs::remove(path);
}

TEST(SimNv, OperateBaudComesFromNvBaudRateAfterReset) {
  DeviceOptions o;
  o.mode = FramingMode::Operate;
  Bench b(o);
  EXPECT_EQ(b.card.baud(), 2500000u);
  b.card.amplifier().poke("NVBAUDRATE", 4);
  EXPECT_EQ(b.card.baud(), 2500000u) << "NV changes nothing live";
  b.card.power_cycle(b.t);
  EXPECT_EQ(b.card.baud(), 115200u);
  Bench setup;
  setup.card.amplifier().poke("NVBAUDRATE", 4);
  setup.card.power_cycle(setup.t);
  EXPECT_EQ(setup.card.baud(), 115200u) << "setup mode is always 115200";
}

}  // namespace
}  // namespace i20::sim::test
