// SPDX-License-Identifier: GPL-2.0-or-later
// Discovery against the simulator started with a shuffled address map: what it finds must
// come from the card, not from the database (issue 4).
#include "device/discover.hpp"

#include <gtest/gtest.h>

#include "device/amp.hpp"
#include "sim/param_map.hpp"
#include "sim/sim_stream.hpp"

using namespace i20;

namespace {

// The 8I20 client's tries and poll pauses, named here (the programs' are in ops/core/timing.hpp).
constexpr device::AmpTiming kAmpTiming{.leave_mode_tries = 2u,
                                       .reset_poll = std::chrono::milliseconds(20),
                                       .clear_fault_poll = std::chrono::milliseconds(5)};

struct Rig {
  explicit Rig(std::uint64_t seed) {
    sim::SimOptions options;
    card_map = sim::register_map_from(db).shuffled(seed);
    options.device.map = card_map;
    link = sim::make_sim_link(std::move(options), {.base_timeout = std::chrono::milliseconds(50),
                                                   .retries = 0u,
                                                   .max_drain = std::chrono::milliseconds(500)});
  }
  std::uint16_t card_address(const std::string& name) const { return card_map.at(name).address; }

  params::ParamDb db = params::ParamDb::builtin();
  sim::RegisterMap card_map;
  std::unique_ptr<link::Link> link;
};

const device::Finding& finding(const device::DiscoveryReport& r, const std::string& name) {
  for (const auto& f : r.findings)
    if (f.name == name) return f;
  throw std::runtime_error("no finding for " + name);
}

device::DiscoveryOptions whole_map_range() {
  device::DiscoveryOptions o{.reset_wait = std::chrono::milliseconds(3000)};
  o.scan_begin = 0x0000;  // the shuffled simulator map uses 0x0400..0x0FFF
  o.scan_end = 0x1000;
  return o;
}

}  // namespace

TEST(Discover, RpcTableNamesTheCycleRegistersOfAShuffledMap) {
  Rig rig(7);
  device::Amp8i20 amp(*rig.link, rig.db, kAmpTiming);
  const auto report = device::discover(amp, whole_map_range());
  for (const char* name : {"ANGLE", "QSETPOINT", "BUSV", "TEMPERATURE", "FAULT", "STATUS"}) {
    const auto& f = finding(report, name);
    EXPECT_EQ(f.outcome, device::Search::Found) << name;
    EXPECT_EQ(f.method, device::Method::RpcTable) << name;
    EXPECT_EQ(f.address, rig.card_address(name)) << name;
    EXPECT_NE(f.address, rig.db.get(name).address)
        << name << ": the shuffled map must differ from the database";
  }
  EXPECT_NE(report.swrevision, *rig.db.simulator_swrevision());
}

TEST(Discover, UniqueNvValuesLocateTheirWorkingTwins) {
  Rig rig(11);
  device::Amp8i20 amp(*rig.link, rig.db, kAmpTiming);
  // Make every NV value distinct (NV addresses are public, so these writes are allowed),
  // the way the report tells a user to resolve ambiguity.
  const std::pair<const char*, std::int64_t> unique[] = {
      {"NVKDP", 51}, {"NVKDI", 150001}, {"NVKDIL", 2001}, {"NVDEADZONE", 17}};
  // NVDEADZONE's EEPROM address is the simulator's own, not a public fact.
  for (const auto& [name, value] : unique) amp.write(name, value, {.allow_unverified = true});
  const auto report = device::discover(amp, whole_map_range());
  for (const char* name : {"MAXCURRENT", "KQP", "KQI", "KQIL", "KDP", "KDI", "KDIL", "DEADZONE", "BUSUNDERV",
                           "BUSOVERV", "BRAKEONV", "BRAKEOFFV"}) {
    const auto& f = finding(report, name);
    EXPECT_EQ(f.outcome, device::Search::Found) << name << ": " << f.detail;
    EXPECT_EQ(f.method, device::Method::UniqueValueMatch) << name;
    EXPECT_EQ(f.address, rig.card_address(name)) << name;
  }
  EXPECT_TRUE(report.was_reset);
}

TEST(Discover, EqualNvValuesAreReportedAmbiguousNotGuessed) {
  Rig rig(3);
  device::Amp8i20 amp(*rig.link, rig.db, kAmpTiming);
  const auto report = device::discover(amp, whole_map_range());  // KQP = KDP = 50 by default
  const auto& kqp = finding(report, "KQP");
  EXPECT_EQ(kqp.outcome, device::Search::Ambiguous);
  EXPECT_FALSE(kqp.address);
  EXPECT_EQ(kqp.candidates.size(), 2u);
  EXPECT_NE(std::find(kqp.candidates.begin(), kqp.candidates.end(), rig.card_address("KQP")),
            kqp.candidates.end());
  EXPECT_NE(std::find(kqp.candidates.begin(), kqp.candidates.end(), rig.card_address("KDP")),
            kqp.candidates.end());
  EXPECT_EQ(finding(report, "CLEARFAULT").outcome, device::Search::NotSearchable);
}

TEST(Discover, OverlayConfirmsFindingsForThisRevisionOnly) {
  Rig rig(7);
  device::Amp8i20 amp(*rig.link, rig.db, kAmpTiming);
  const auto report = device::discover(amp, whole_map_range());
  const auto yaml = report.overlay_yaml("test");
  params::ParamDb loaded = params::ParamDb::builtin();
  loaded.apply_overlay_string(yaml, "discovered.yaml");
  EXPECT_EQ(loaded.get("BRAKEONV").address, rig.db.get("BRAKEONV").address) << "waits for its revision";
  const params::ParamDb db = loaded.for_firmware(report.swrevision);
  EXPECT_EQ(db.get("BRAKEONV").address, rig.card_address("BRAKEONV"));
  EXPECT_TRUE(db.address_confirmed(db.get("BRAKEONV")));
  EXPECT_FALSE(db.get("KQP").address) << "ambiguous: unknown on this revision, not the database's guess";
  // With the overlay, a working write lands where the card keeps BRAKEONV.
  device::Amp8i20 amp2(*rig.link, db, kAmpTiming);
  amp2.write("BRAKEONV", 30000, {});
  EXPECT_EQ(amp2.read_memory(params::Space::Ram, rig.card_address("BRAKEONV"), 2), (lbp::Bytes{0x30, 0x75}));
}

TEST(Discover, SendsNoParameterWrites) {
  Rig rig(5);
  device::Amp8i20 amp(*rig.link, rig.db, kAmpTiming);
  auto options = whole_map_range();
  options.reset_first = false;
  const auto before = device::discover(amp, options);
  // Nothing changed on the card: a second pass reads the same RAM and finds the same.
  const auto again = device::discover(amp, options);
  ASSERT_EQ(before.findings.size(), again.findings.size());
  for (std::size_t i = 0; i < before.findings.size(); ++i)
    EXPECT_EQ(before.findings[i].address, again.findings[i].address);
}
