// SPDX-License-Identifier: GPL-2.0-or-later
// The fault and status knowledge base loader (lib/faults, params/faults.yaml format),
// and decoding every register value against a table it accepted.
#include "faults/fault_table.hpp"

#include <cstddef>
#include <cstdint>

#include "faults/decode.hpp"
#include "fuzz_support.hpp"

namespace {

using namespace i20;

void run(std::string_view text) {
  const auto table = faults::FaultTable::load_string(text, "fuzz.yaml");
  for (unsigned bit = 0; bit < 16; ++bit) {
    (void)faults::decode_fault(static_cast<std::uint16_t>(1u << bit), table);
    (void)faults::decode_status(static_cast<std::uint16_t>(1u << bit), table);
  }
  (void)faults::decode_fault(0xFFFF, table);
  (void)faults::decode_status(0xFFFF, table);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::expect_only_toolkit_errors([&] { run(fuzz::text_of(data, size)); });
  return 0;
}
