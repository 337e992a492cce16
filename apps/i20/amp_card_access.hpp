// The profile engine's CardAccess over the device layer's Amp8i20 client.
//
// Every value that leaves here was read from the card: a write returns only after the card
// read back the value written; anything less throws, and the engine rolls back.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>

#include "device/amp.hpp"
#include "profile/card_access.hpp"

namespace i20::cli {

struct CardAccessOptions {
  device::WriteOptions write;  // force (guarded parameters), allow_unverified (RAM addresses)
  // Attempts per read, and per write whose reply was lost or garbled. A line that
  // drops a byte now and then should not roll back a whole apply; every retry is
  // counted and every result is still proved by a read-back.
  unsigned attempts = 3;
  std::string where;  // the target as the user named it, for describe()
};

class AmpCardAccess final : public profile::CardAccess {
 public:
  // Told what the card client is doing, for progress displays: "reading",
  // "writing NVBRAKEONV (2/5)", "restoring NVBRAKEONV", "resetting".
  using Activity = std::function<void(const std::string&)>;

  AmpCardAccess(device::Amp8i20& amp, CardAccessOptions options, Activity activity = {});

  profile::RawValues read(const std::vector<std::string>& names) override;
  void check_write(const std::string& name, std::int64_t raw) override;
  void write(const std::string& name, std::int64_t raw) override;
  void reset() override;
  std::string describe() override;

  // Did check_write() refuse a value (the device layer's safety rules)?
  bool refused() const { return refused_; }
  // Reads and writes repeated after a lost or garbled reply.
  std::size_t retries() const { return retries_; }
  // Was the apply interrupted (Ctrl-C)?
  bool interrupted() const { return interrupted_; }

 private:
  profile::RawValues read_once(const std::vector<std::string>& names);
  void write_once(const std::string& name, std::int64_t raw);
  bool holds(const std::string& name, std::int64_t raw);
  void stop_if_interrupted();
  void note(const std::string& what);

  device::Amp8i20& amp_;
  CardAccessOptions options_;
  Activity activity_;
  std::string description_;
  std::size_t planned_ = 0;  // check_write() calls: the engine asks once per planned write
  std::size_t written_ = 0;
  bool failed_ = false;  // a write failed: later writes restore the backup
  bool refused_ = false;
  bool interrupted_ = false;
  std::size_t retries_ = 0;
};

}  // namespace i20::cli
