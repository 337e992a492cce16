// SPDX-License-Identifier: GPL-2.0-or-later
// Manual "FAULT CONDITIONS", "CLEARING FAULTS", "FAULT MASK", "STATUS REGISTER",
// "MOTOR BRAKE"; docs/facts.md s4 (LinuxCNC's extra STATUS bits). Everything is read back
// over LBP, as a host would.
#include "bench.hpp"
#include "sim/bits.hpp"

namespace i20::sim::test {
namespace {

class SimFault : public ::testing::Test {
 protected:
  std::uint16_t fault() { return static_cast<std::uint16_t>(b.read("FAULT")); }
  std::uint16_t status() { return static_cast<std::uint16_t>(b.read("STATUS")); }
  void clearfault() {
    EXPECT_EQ(b.write16(b.address_of("CLEARFAULT"), 1), lbp::Bytes{0x00});
    EXPECT_EQ(b.read("CLEARFAULT"), 1u) << "the card acts after a short delay";
    b.wait(10ms);
  }
  WorldSettings& world() { return b.card.world().settings(); }
  Bench b;
};

TEST_F(SimFault, HealthyCardAtPowerUp) {
  EXPECT_EQ(fault(), 0u);
  EXPECT_EQ(status(), status::kExternalReset) << "EXTR only; setup mode runs no current loop";
  EXPECT_FALSE(b.card.amplifier().fault_output_active());
  EXPECT_EQ(b.read("BUSV"), 32000u);
  EXPECT_EQ(b.read("TEMPERATURE"), 3500u);
}

TEST_F(SimFault, NoEnable) {
  world().enable = false;
  EXPECT_EQ(fault(), fault::kNoEnable);
  EXPECT_TRUE(status() & status::kNoEnable);
  EXPECT_TRUE(b.card.amplifier().fault_output_active());
}

TEST_F(SimFault, BusUnderVoltage) {
  world().bus_volts = 30;  // below BUSUNDERV 35 V
  EXPECT_EQ(fault(), fault::kBusLow);
  EXPECT_TRUE(status() & status::kBusUnderV);
}

TEST_F(SimFault, BusOverVoltageSettableAndFixed) {
  b.write16(b.address_of("BUSOVERV"), 30000);
  world().bus_volts = 310;
  EXPECT_EQ(fault(), fault::kBusHigh) << "working BUSOVERV applies live";
  world().bus_volts = 401;
  EXPECT_EQ(fault() & fault::kBusMax, fault::kBusMax) << "fixed 400 V limit";
}

TEST_F(SimFault, FixedLimitHoldsEvenWithAHighSetting) {
  b.write16(b.address_of("BUSOVERV"), 45000);
  world().bus_volts = 405;
  EXPECT_EQ(fault(), fault::kBusMax);
}

TEST_F(SimFault, OverTemperatureAndCurrentLimiting) {
  world().temperature_c = 75;
  EXPECT_EQ(fault(), 0u);
  EXPECT_TRUE(status() & status::kCurrentLimited);
  world().temperature_c = 86;
  EXPECT_EQ(fault(), fault::kOverTemp);
}

TEST_F(SimFault, HardwareCausesFromTheWorld) {
  for (std::uint16_t bit : {fault::kOverCurrent, fault::kULoop, fault::kVLoop, fault::kWLoop, fault::kModule,
                            fault::kSerialOverrun, fault::kSerialFraming}) {
    world().forced_faults = bit;
    EXPECT_EQ(fault() & bit, bit) << bit;
  }
}

TEST_F(SimFault, FaultsLatchUntilClearfault) {
  world().enable = false;
  EXPECT_EQ(fault(), fault::kNoEnable);
  world().enable = true;
  EXPECT_EQ(fault(), fault::kNoEnable) << "latched although the cause is gone";
  EXPECT_EQ(b.write16(b.address_of("FAULT"), 0), lbp::Bytes{0x00});
  EXPECT_EQ(fault(), fault::kNoEnable) << "FAULT is not writable";
  clearfault();
  EXPECT_EQ(b.read("CLEARFAULT"), 0u) << "the card sets CLEARFAULT back to 0";
  EXPECT_EQ(fault(), 0u);
}

TEST_F(SimFault, ClearfaultKeepsFaultsWhoseCauseRemains) {
  world().enable = false;
  world().bus_volts = 20;
  fault();
  world().bus_volts = 48;  // under-voltage gone, enable still off
  clearfault();
  EXPECT_EQ(fault(), fault::kNoEnable);
  EXPECT_EQ(b.read("CLEARFAULT"), 0u);
}

TEST_F(SimFault, ClearfaultDelayIsConfigurable) {
  DeviceOptions o;
  o.amplifier.clearfault_delay = 50ms;
  Bench slow(o);
  slow.write16(slow.address_of("CLEARFAULT"), 1);
  slow.wait(20ms);
  EXPECT_EQ(slow.read("CLEARFAULT"), 1u);
  slow.wait(40ms);
  EXPECT_EQ(slow.read("CLEARFAULT"), 0u);
}

TEST_F(SimFault, OnlyBusUnderVoltageIsMaskable) {
  world().bus_volts = 20;
  fault();
  EXPECT_TRUE(b.card.amplifier().fault_output_active());
  b.write16(b.address_of("FAULTMASK"), 0xFEFF);
  b.wait(1ms);
  EXPECT_FALSE(b.card.amplifier().fault_output_active()) << "bit 8 masked from the fault output";
  EXPECT_EQ(fault(), fault::kBusLow) << "still reported in FAULT";
  world().enable = false;
  b.write16(b.address_of("FAULTMASK"), 0xFEFD);  // tries to mask bit 1 as well
  fault();
  EXPECT_TRUE(b.card.amplifier().fault_output_active()) << "NOENABLEFAULT cannot be masked";
}

TEST_F(SimFault, BrakeHysteresis) {
  auto brake = [&] { return (status() & status::kBrakeOn) != 0; };
  world().bus_volts = 350;
  EXPECT_FALSE(brake());
  world().bus_volts = 361;  // above BRAKEONV 360
  EXPECT_TRUE(brake());
  world().bus_volts = 350;  // between off (340) and on: stays on
  EXPECT_TRUE(brake());
  world().bus_volts = 339;
  EXPECT_FALSE(brake());
  world().bus_volts = 350;
  EXPECT_FALSE(brake()) << "between the thresholds: stays off";
  EXPECT_TRUE(status() & status::kBrakeWasOn) << "sticky";
}

TEST_F(SimFault, FixedBrakeOnAt385) {
  b.write16(b.address_of("BRAKEONV"), 39500);
  b.write16(b.address_of("BRAKEOFFV"), 39000);
  world().bus_volts = 384;
  EXPECT_FALSE(status() & status::kBrakeOn);
  world().bus_volts = 386;
  EXPECT_TRUE(status() & status::kBrakeOn) << "the fixed 385 V brake-on protects the module";
}

TEST_F(SimFault, StickyStatusBitsAndWhatClearsThem) {
  EXPECT_TRUE(status() & status::kExternalReset);
  b.send("FE 5A");
  b.wait(2ms);
  EXPECT_EQ(status() & status::kSticky, status::kExternalReset | status::kSoftwareReset);
  world().bus_volts = 370;
  status();
  world().bus_volts = 300;
  EXPECT_EQ(status() & status::kSticky,
            status::kExternalReset | status::kSoftwareReset | status::kBrakeWasOn);
  clearfault();
  EXPECT_EQ(status() & status::kSticky, 0u) << "simulator's reading: CLEARFAULT clears the status register";
  b.card.power_cycle(b.t);
  EXPECT_EQ(status() & status::kSticky, status::kExternalReset) << "power removal forgets everything else";
}

TEST_F(SimFault, ResetCopiesNvIntoWorkingAndRecomputesFaults) {
  world().enable = false;
  fault();
  world().enable = true;
  b.write16(b.address_of("BRAKEONV"), 30000);
  b.send("FE 5A");
  b.wait(2ms);
  EXPECT_EQ(b.read("BRAKEONV"), 36000u);
  EXPECT_EQ(fault(), 0u) << "a reset starts with the faults present now";
}

class SimWatchdog : public ::testing::Test {
 protected:
  static DeviceOptions operate() {
    DeviceOptions o;
    o.mode = FramingMode::Operate;
    return o;
  }
  // Operate mode needs a gap after each packet.
  lbp::Bytes exchange(std::string_view hex) {
    b.send(hex);
    return b.wait(200us);
  }
  std::uint16_t read_fault() {
    const auto out = exchange("45 00 08");
    return out.size() == 3 ? static_cast<std::uint16_t>(out[0] | out[1] << 8) : 0xFFFF;
  }
  Bench b{operate()};
};

TEST_F(SimWatchdog, BitesAfter40MsWithoutAValidCommand) {
  EXPECT_EQ(read_fault(), 0u);
  EXPECT_EQ(b.card.amplifier().status() & status::kCurrentLoopOn, status::kCurrentLoopOn);
  b.wait(30ms);
  EXPECT_EQ(read_fault(), 0u) << "fed in time";
  b.wait(45ms);
  EXPECT_EQ(read_fault(), fault::kWatchdog);
  EXPECT_EQ(b.card.amplifier().status() & status::kCurrentLoopOn, 0u) << "a fault stops the current loop";
  const auto st = exchange("C1");
  ASSERT_EQ(st.size(), 2u);
  EXPECT_TRUE(st[0] & lbp::local::kStatusWatchdog);
}

TEST_F(SimWatchdog, NotInSetupMode) {
  Bench setup;
  setup.send("DF");
  setup.wait(500ms);
  EXPECT_EQ(setup.read("FAULT"), 0u);
}

}  // namespace
}  // namespace i20::sim::test
