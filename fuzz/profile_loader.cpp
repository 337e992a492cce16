// SPDX-License-Identifier: GPL-2.0-or-later
// The profile loader (lib/profile/loader) and what runs on an accepted profile before
// any card is touched: validation, the write plan against the database defaults, and
// saving it back as YAML, which must load again to the same settings.
#include <cstddef>
#include <cstdint>
#include <optional>

#include "fuzz_support.hpp"
#include "params/param_db.hpp"
#include "profile/loader.hpp"
#include "profile/validate.hpp"
#include "profile/writer.hpp"

namespace {

using namespace i20;

const params::ParamDb& db() {
  static const params::ParamDb instance = params::ParamDb::builtin();
  return instance;
}

// A profile the loader accepted: validation never throws, and it saves to YAML that
// loads back to the same settings (writer.hpp's promise).
void accepted(const profile::Profile& p) {
  (void)profile::validate(p, db());
  const std::string saved = profile::to_yaml(p, db());
  const auto again = profile::load_profile_string(saved, "saved.yaml", db());
  fuzz::require(again.settings.size() == p.settings.size(), "a saved profile keeps every setting");
  for (std::size_t i = 0; i < p.settings.size(); ++i) {
    fuzz::require(again.settings[i].name == p.settings[i].name, "a saved profile keeps the names");
    fuzz::require(again.settings[i].raw == p.settings[i].raw, "a saved profile keeps the values");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::optional<profile::Profile> loaded;
  fuzz::expect_only_toolkit_errors(
      [&] { loaded = profile::load_profile_string(fuzz::text_of(data, size), "fuzz.yaml", db()); });
  if (loaded) fuzz::expect_no_exception([&] { accepted(*loaded); });
  return 0;
}
