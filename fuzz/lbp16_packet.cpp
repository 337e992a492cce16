// SPDX-License-Identifier: GPL-2.0-or-later
// LBP16 packet decoding (7I96S/7I92T manuals, "LBP16 COMMANDS", "INFO AREA"): the card
// side's request parser, the host side's reply splitter, and the info/board-info parsers,
// on arbitrary bytes. A request that parses re-encodes to the same bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "lbp16/lbp16.hpp"

namespace {

using namespace i20;
namespace l16 = lbp::lbp16;

void request(lbp::ByteView packet) {
  const auto parsed = l16::parse_request(packet);
  std::size_t used = 0;
  for (const auto& c : parsed.commands) used += c.request_bytes();
  fuzz::require(used <= packet.size(), "parsed commands fit in the packet");
  if (parsed.error)
    fuzz::require(parsed.error_offset == used, "the parse stops where the commands end");
  else
    fuzz::require(used == packet.size(), "a packet without error is all commands");
  if (parsed.commands.empty()) return;
  fuzz::expect_only_toolkit_errors([&] {
    // encode_packet refuses packets beyond one Ethernet frame; those are fine to refuse.
    const lbp::Bytes again = l16::encode_packet(parsed.commands);
    fuzz::require(again.size() == used && std::equal(again.begin(), again.end(), packet.begin()),
                  "a parsed request re-encodes to its bytes");
  });
  // The reply to these commands, split back: exact size accepted, any other refused.
  const std::size_t reply_size = l16::reply_bytes(parsed.commands);
  if (reply_size > 4 * l16::kMaxPayload) return;
  const lbp::Bytes reply(reply_size, 0xA5);
  const auto parts = l16::split_reply(parsed.commands, reply);
  fuzz::require(parts.size() == parsed.commands.size(), "one reply part per command");
  for (std::size_t i = 0; i < parts.size(); ++i)
    fuzz::require(parts[i].size() == parsed.commands[i].reply_bytes(), "each part has its command's size");
  fuzz::expect_only_toolkit_errors([&] {
    (void)l16::split_reply(parsed.commands, packet);  // the wrong size, usually
  });
}

void parsers(lbp::ByteView bytes) {
  fuzz::expect_only_toolkit_errors([&] { (void)l16::InfoArea::parse(bytes); });
  fuzz::expect_only_toolkit_errors([&] { (void)l16::BoardInfo::parse(bytes); });
  if (bytes.size() >= l16::kInfoAreaBytes) {
    const auto info = l16::InfoArea::parse(bytes.first(l16::kInfoAreaBytes));
    fuzz::require(info.name.size() <= 8, "an info area name has at most 8 characters");
  }
  if (bytes.size() >= 2) {
    const auto word = static_cast<std::uint16_t>(bytes[0] | (bytes[1] << 8));
    fuzz::expect_only_toolkit_errors([&] {
      const auto decoded = l16::CommandWord::decode(word);
      fuzz::require(decoded.encode() == word, "a command word round-trips");
    });
    fuzz::require(l16::MemSizes::decode(word).encode() == (word & 0xFF0F), "MemSizes keeps W, type and mask");
  }
  (void)l16::words16(bytes);
  (void)l16::words32(bytes);
  (void)l16::text_of(bytes);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const lbp::ByteView bytes(data, size);
  fuzz::expect_only_toolkit_errors([&] { request(bytes); });
  fuzz::expect_only_toolkit_errors([&] { parsers(bytes); });
  return 0;
}
