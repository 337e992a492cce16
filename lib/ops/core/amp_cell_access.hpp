// SPDX-License-Identifier: GPL-2.0-or-later
// The transaction's CellAccess over an open ops::Amp: the one place where the retry policy
// meets writes, and where what the card did meanwhile (it reset itself, a stray write had
// to be cleared) is recorded for the report.
//
// Every value that leaves here was read from the card: a write returns only after the card
// read back the value written; anything less throws, and the transaction rolls back.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "device/amp.hpp"
#include "ops/core/amp.hpp"
#include "ops/core/cell_access.hpp"

namespace i20::ops {

class AmpCellAccess final : public CellAccess {
 public:
  // Told what the card client is doing, for progress displays: "reading",
  // "writing NVBRAKEONV (2/5)", "restoring NVBRAKEONV", "resetting".
  using Activity = std::function<void(const std::string&)>;

  AmpCellAccess(Amp& amp, device::WriteOptions write, Activity activity = {});

  RawValues read(const std::vector<std::string>& names) override;
  void check_write(const std::string& name, std::int64_t raw) override;
  void write(const std::string& name, std::int64_t raw) override;
  void reset() override;
  void way_back() override;
  std::string describe() override { return amp_.describe(); }
  std::vector<std::string> events() const override { return events_; }

  // Did check_write() refuse a value (the device layer's safety rules)?
  bool refused() const { return refused_; }

 private:
  void write_once(const std::string& name, std::int64_t raw);
  void recover_from_mode_loss(const device::NvModeLost& lost);
  // Whether the card holds `raw` in `name`, read back within the retry budget; nullopt when
  // the read-back got no answer either (the write's fate is then unknown).
  std::optional<bool> holds(const std::string& name, std::int64_t raw);
  void note(const std::string& what);

  Amp& amp_;
  Amp::Uninterruptible uninterruptible_;
  std::optional<Amp::Settling> settling_;  // from way_back() on
  device::WriteOptions write_;
  Activity activity_;
  std::size_t planned_ = 0;  // check_write() calls: the transaction asks once per planned write
  std::size_t written_ = 0;
  bool failed_ = false;  // a write failed: later writes restore the old values
  bool refused_ = false;
  std::vector<std::string> events_;
};

}  // namespace i20::ops
