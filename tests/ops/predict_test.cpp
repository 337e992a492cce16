// SPDX-License-Identifier: GPL-2.0-or-later
// Predictions use the code of the real action: a dry run is refused exactly where the apply
// would be (the device layer's rules too), and "pending" NV values are every NV cell whose
// working twin holds something else, on the whole card.
#include <gtest/gtest.h>

#include "fake_cell_access.hpp"
#include "ops/apply_run.hpp"
#include "ops/core/pending.hpp"
#include "ops/core/transaction.hpp"
#include "sim_rig.hpp"
#include "test_util.hpp"

using namespace i20::ops;
using namespace i20::ops::testing;
using namespace i20::profile::testing;

namespace {

const std::string kBrake = with_params("  NVBRAKEOFFV: 170 V\n  NVBRAKEONV: 190 V\n");

}  // namespace

TEST(OpsPredict, ADryRunIsRefusedByTheDeviceRulesAsTheApplyIs) {
  FakeCard card{db()};
  card.refuse_writes_to = {"NVBRAKEONV"};
  TransactionOptions options;
  options.dry_run = true;
  const auto dry = run_transaction(load(kBrake), db(), card, options);
  options.dry_run = false;
  const auto real = run_transaction(load(kBrake), db(), card, options);
  EXPECT_EQ(real.outcome, Outcome::Refused) << real.reason;
  EXPECT_EQ(dry.outcome, real.outcome) << "the dry run predicted: " << dry.reason;
  EXPECT_EQ(dry.reason, real.reason);
  EXPECT_EQ(card.write_calls, 0);
}

TEST(OpsPredict, PendingNvValuesAreThePairsThatDiffer) {
  const RawValues values{{"NVBRAKEONV", 19000},
                         {"BRAKEONV", 36000},  // pending
                         {"NVMAXCURRENT", 1200},
                         {"MAXCURRENT", 1200},  // live
                         {"NVKQP", 50}};        // twin unknown: not judged
  EXPECT_EQ(pending_nv_values(db(), values), std::vector<std::string>{"NVBRAKEONV"});
  EXPECT_TRUE(pending_nv_values(db(), {}).empty());
}

// Two writes by two commands: the second one's "not live yet" counts the first one's too,
// judged against what the simulator holds.
TEST(OpsPredict, NotLiveCountsEveryPendingValueOnTheCard) {
  SimRig rig(RigOptions().bus(160));
  auto amp = rig.open();
  const auto first = load(kBrake, amp->db());
  ApplyJob job;
  job.profile = &first;
  job.db = &amp->db();
  auto run = run_apply_on(*amp, job);
  ASSERT_EQ(run.outcome, Outcome::Done) << (run.result ? run.result->reason : run.error);
  EXPECT_EQ(run.not_live.size(), 2u);
  const auto second = load(with_params("  NVMAXCURRENT: 11 A\n"), amp->db());
  job.profile = &second;
  run = run_apply_on(*amp, job);
  ASSERT_EQ(run.outcome, Outcome::Done) << (run.result ? run.result->reason : run.error);
  EXPECT_EQ(run.not_live, (std::vector<std::string>{"NVMAXCURRENT", "NVBRAKEONV", "NVBRAKEOFFV"}))
      << "in database order";
  EXPECT_EQ(pending_nv_values(*amp), run.not_live);
}
