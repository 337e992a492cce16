// SPDX-License-Identifier: GPL-2.0-or-later
// The parameter database loader with overlays (lib/params): a whole database, an overlay
// on the shipped one (now, or waiting for a firmware revision), or two overlays in a row.
// Whatever it accepts must be a consistent database: every range fits its width, every
// address fits the 16-bit space.
//
// Input: [mode][revision: 2 bytes][YAML text; in mode 2 two texts split at the first NUL]
#include "params/param_db.hpp"

#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "params/value.hpp"

namespace {

using namespace i20;
using params::ParamDb;

void check(const ParamDb& db) {
  for (const auto& p : db.all()) {
    fuzz::require(p.width_bits == 8 || p.width_bits == 16 || p.width_bits == 32, "widths are 8, 16 or 32");
    fuzz::require(p.min <= p.max, "min <= max");
    const std::int64_t top =
        p.is_signed ? (std::int64_t{1} << (p.width_bits - 1)) - 1 : (std::int64_t{1} << p.width_bits) - 1;
    fuzz::require(p.max <= top, "max fits the width");
    fuzz::require(p.scale > 0, "scale is positive");
    fuzz::require(!p.address || std::size_t{*p.address} + p.bytes() <= 0x10000, "addresses stay in 64K");
    fuzz::require(db.find(p.name) == &p, "names are unique");
    // The value layer copes with whatever the loader accepted.
    for (auto raw : {p.min, p.max}) {
      const std::string shown = params::format_engineering(p, raw);
      params::check_range(p, raw);
      const auto bytes = params::bytes_from_raw(p, raw);
      fuzz::require(params::raw_from_bytes(p, bytes) == raw, "a value in range survives the wire");
      fuzz::expect_only_toolkit_errors([&] { (void)params::parse_value(p, shown); });
    }
  }
}

void run(fuzz::Input& in) {
  const std::uint8_t mode = in.byte() % 3;
  const std::uint16_t revision = in.u16();
  const std::string text = in.rest_text();
  if (mode == 0) {
    check(ParamDb::load_string(text, "fuzz.yaml"));
    return;
  }
  ParamDb db = ParamDb::builtin();
  if (mode == 1) {
    db.apply_overlay_string(text, "overlay.yaml");
  } else {
    const auto split = text.find('\0');
    db.apply_overlay_string(text.substr(0, split), "first.yaml");
    if (split != std::string::npos) db.apply_overlay_string(text.substr(split + 1), "second.yaml");
  }
  check(db);
  check(db.for_firmware(revision));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  fuzz::expect_only_toolkit_errors([&] { run(in); });
  return 0;
}
