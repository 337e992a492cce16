// SPDX-License-Identifier: GPL-2.0-or-later
// Register values as users paste them into `i20 faults decode` (lib/faults/
// register_value): hex, h-suffixed hex, binary with '_' groups, decimal. Refused text
// throws BadRegisterValue; an accepted value reads back from its own hex form, and the
// decoder explains it.
#include <cstddef>
#include <cstdint>

#include "faults/decode.hpp"
#include "faults/register_value.hpp"
#include "fuzz_support.hpp"
#include "lbp/bytes.hpp"

namespace {

using namespace i20;

void run(std::string_view text) {
  const std::uint16_t v = faults::parse_register_value(text, "FAULT");
  fuzz::require(faults::parse_register_value(lbp::hex_value(v, 4)) == v,
                "a value reads back from its hex form");
  fuzz::require(faults::parse_register_value(std::to_string(v)) == v,
                "a value reads back from its decimal form");
  (void)faults::decode_fault(v);
  (void)faults::decode_status(v);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::expect_only_toolkit_errors([&] { run(fuzz::text_of(data, size)); });
  return 0;
}
