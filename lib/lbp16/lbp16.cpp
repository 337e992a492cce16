// SPDX-License-Identifier: GPL-2.0-or-later
#include "lbp16/lbp16.hpp"

#include <algorithm>

#include "lbp/error.hpp"

namespace i20::lbp::lbp16 {
namespace {

constexpr std::uint16_t kWriteBit = 0x8000;
constexpr std::uint16_t kAddressBit = 0x4000;
constexpr std::uint16_t kInfoBit = 0x2000;
constexpr unsigned kSpaceShift = 10;
constexpr unsigned kWidthShift = 8;
constexpr std::uint16_t kIncrementBit = 0x0080;
constexpr std::uint16_t kCountMask = 0x007F;

void require_count(unsigned count) {
  if (count == 0 || count > kMaxCount)
    throw UsageError("an LBP16 command moves 1 to 127 elements, not " + std::to_string(count));
}

void require_space(unsigned space) {
  if (space >= kSpaceCount) throw UsageError("LBP16 has memory spaces 0 to 7, not " + std::to_string(space));
}

Command make(CommandWord word, std::optional<std::uint16_t> address, ByteView data) {
  require_space(word.space);
  Command c{.word = word, .address = address, .data = Bytes(data.begin(), data.end())};
  c.word.has_address = address.has_value();
  return c;
}

Command make_write(std::uint8_t space, std::optional<std::uint16_t> address, Width width, ByteView data,
                   bool increment) {
  const std::size_t element = bytes_of(width);
  if (data.empty() || data.size() % element != 0)
    throw UsageError("LBP16 write data must be a whole number of " + std::to_string(element) +
                     "-byte elements, got " + std::to_string(data.size()) + " bytes");
  const std::size_t count = data.size() / element;
  require_count(static_cast<unsigned>(std::min<std::size_t>(count, 1000)));
  CommandWord word{.write = true,
                   .space = space,
                   .width = width,
                   .increment = increment,
                   .count = static_cast<std::uint8_t>(count)};
  return make(word, address, data);
}

void check_consistent(const Command& c) {
  if (c.word.has_address != c.address.has_value())
    throw UsageError("LBP16 command word and address disagree (A bit vs address present)");
  const std::size_t expected = c.word.write ? c.word.data_bytes() : 0;
  if (c.data.size() != expected)
    throw UsageError("LBP16 command carries " + std::to_string(c.data.size()) +
                     " data bytes, its word says " + std::to_string(expected));
}

}  // namespace

std::size_t bytes_of(Width width) {
  return std::size_t{1} << static_cast<unsigned>(width);
}

std::uint16_t CommandWord::encode() const {
  require_count(count);
  require_space(space);
  std::uint16_t w = static_cast<std::uint16_t>(space << kSpaceShift) |
                    static_cast<std::uint16_t>(static_cast<unsigned>(width) << kWidthShift) | count;
  if (write) w |= kWriteBit;
  if (has_address) w |= kAddressBit;
  if (info_area) w |= kInfoBit;
  if (increment) w |= kIncrementBit;
  return w;
}

CommandWord CommandWord::decode(std::uint16_t word) {
  const auto count = static_cast<std::uint8_t>(word & kCountMask);
  if (count == 0) throw ProtocolError("LBP16 command word with a transfer count of 0");
  return CommandWord{.write = (word & kWriteBit) != 0,
                     .has_address = (word & kAddressBit) != 0,
                     .info_area = (word & kInfoBit) != 0,
                     .space = static_cast<std::uint8_t>((word >> kSpaceShift) & 0x7),
                     .width = static_cast<Width>((word >> kWidthShift) & 0x3),
                     .increment = (word & kIncrementBit) != 0,
                     .count = count};
}

Command read(std::uint8_t space, std::uint16_t address, Width width, unsigned count, bool increment) {
  require_count(count);
  return make(
      {.space = space, .width = width, .increment = increment, .count = static_cast<std::uint8_t>(count)},
      address, {});
}

Command read_at_pointer(std::uint8_t space, Width width, unsigned count, bool increment) {
  require_count(count);
  return make(
      {.space = space, .width = width, .increment = increment, .count = static_cast<std::uint8_t>(count)},
      std::nullopt, {});
}

Command write(std::uint8_t space, std::uint16_t address, Width width, ByteView data, bool increment) {
  return make_write(space, address, width, data, increment);
}

Command write_at_pointer(std::uint8_t space, Width width, ByteView data, bool increment) {
  return make_write(space, std::nullopt, width, data, increment);
}

Command read_info(std::uint8_t space, std::uint16_t address, unsigned count) {
  Command c = read(space, address, Width::Bits16, count, true);
  c.word.info_area = true;
  return c;
}

Command read_hm2(std::uint16_t address, unsigned count) {
  return read(space::kHostMot2, address, Width::Bits32, count, true);
}

Command write_hm2(std::uint16_t address, std::uint32_t value) {
  return write_hm2(address, std::span<const std::uint32_t>(&value, 1));
}

Command write_hm2(std::uint16_t address, std::span<const std::uint32_t> values) {
  const Bytes data = bytes_of_words(values);
  return write(space::kHostMot2, address, Width::Bits32, data, true);
}

Command enable_writes(std::uint8_t space) {
  require_space(space);
  const Bytes data = to_le(kInfoCookieBase | space, 2);
  return write(space::kStatus, kEepromWriteEnableAddress, Width::Bits16, data, false);
}

Bytes encode(const Command& command) {
  check_consistent(command);
  Bytes out;
  append_le(out, command.word.encode(), 2);
  if (command.address) append_le(out, *command.address, 2);
  out.insert(out.end(), command.data.begin(), command.data.end());
  return out;
}

Bytes encode_packet(std::span<const Command> commands) {
  Bytes out;
  for (const Command& c : commands) {
    const Bytes one = encode(c);
    out.insert(out.end(), one.begin(), one.end());
  }
  if (out.size() > kMaxPayload)
    throw UsageError("LBP16 request of " + std::to_string(out.size()) + " bytes exceeds one UDP packet (" +
                     std::to_string(kMaxPayload) + "): split it");
  if (reply_bytes(commands) > kMaxPayload)
    throw UsageError("LBP16 reply of " + std::to_string(reply_bytes(commands)) +
                     " bytes would exceed one UDP packet (" + std::to_string(kMaxPayload) +
                     "): split the reads");
  return out;
}

std::size_t reply_bytes(std::span<const Command> commands) {
  std::size_t total = 0;
  for (const Command& c : commands) total += c.reply_bytes();
  return total;
}

std::vector<Bytes> split_reply(std::span<const Command> commands, ByteView reply) {
  const std::size_t expected = reply_bytes(commands);
  if (reply.size() != expected)
    throw ProtocolError("LBP16 reply of " + std::to_string(reply.size()) + " bytes, expected " +
                        std::to_string(expected));
  std::vector<Bytes> out;
  out.reserve(commands.size());
  std::size_t at = 0;
  for (const Command& c : commands) {
    const std::size_t n = c.reply_bytes();
    out.emplace_back(reply.begin() + static_cast<std::ptrdiff_t>(at),
                     reply.begin() + static_cast<std::ptrdiff_t>(at + n));
    at += n;
  }
  return out;
}

ParseResult parse_request(ByteView packet) {
  ParseResult result;
  std::size_t at = 0;
  const auto fail = [&](std::string why) {
    result.error = std::move(why);
    result.error_offset = at;
    return result;
  };
  while (at < packet.size()) {
    if (packet.size() - at < 2) return fail("packet ends inside an LBP16 command word");
    const auto raw = static_cast<std::uint16_t>(read_le(packet.subspan(at, 2)));
    CommandWord word;
    try {
      word = CommandWord::decode(raw);
    } catch (const ProtocolError& e) {
      return fail(e.what());
    }
    std::size_t need = 2 + (word.has_address ? 2 : 0) + (word.write ? word.data_bytes() : 0);
    if (packet.size() - at < need) return fail("packet ends inside an LBP16 command");
    Command c{.word = word};
    std::size_t p = at + 2;
    if (word.has_address) {
      c.address = static_cast<std::uint16_t>(read_le(packet.subspan(p, 2)));
      p += 2;
    }
    if (word.write)
      c.data.assign(packet.begin() + static_cast<std::ptrdiff_t>(p),
                    packet.begin() + static_cast<std::ptrdiff_t>(at + need));
    result.commands.push_back(std::move(c));
    at += need;
  }
  return result;
}

std::vector<std::uint16_t> words16(ByteView data) {
  std::vector<std::uint16_t> out;
  for (std::size_t i = 0; i + 2 <= data.size(); i += 2)
    out.push_back(static_cast<std::uint16_t>(read_le(data.subspan(i, 2))));
  return out;
}

std::vector<std::uint32_t> words32(ByteView data) {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i + 4 <= data.size(); i += 4)
    out.push_back(static_cast<std::uint32_t>(read_le(data.subspan(i, 4))));
  return out;
}

Bytes bytes_of_words(std::span<const std::uint32_t> words) {
  Bytes out;
  out.reserve(words.size() * 4);
  for (std::uint32_t w : words) append_le(out, w, 4);
  return out;
}

std::uint16_t MemSizes::encode() const {
  return static_cast<std::uint16_t>((writable ? 0x8000 : 0) | ((type & 0x7F) << 8) | (access_mask & 0x0F));
}

MemSizes MemSizes::decode(std::uint16_t word) {
  return MemSizes{.writable = (word & 0x8000) != 0,
                  .type = static_cast<std::uint8_t>((word >> 8) & 0x7F),
                  .access_mask = static_cast<std::uint8_t>(word & 0x0F)};
}

std::uint16_t MemRanges::encode() const {
  return static_cast<std::uint16_t>(((erase_log2 & 0x1F) << 11) | ((page_log2 & 0x1F) << 6) |
                                    (range_log2 & 0x3F));
}

MemRanges MemRanges::decode(std::uint16_t word) {
  return MemRanges{.erase_log2 = static_cast<std::uint8_t>((word >> 11) & 0x1F),
                   .page_log2 = static_cast<std::uint8_t>((word >> 6) & 0x1F),
                   .range_log2 = static_cast<std::uint8_t>(word & 0x3F)};
}

InfoArea InfoArea::parse(ByteView bytes) {
  if (bytes.size() != kInfoAreaBytes)
    throw ProtocolError("an LBP16 info area is 16 bytes, got " + std::to_string(bytes.size()));
  const auto w = words16(bytes);
  return InfoArea{.cookie = w[0],
                  .sizes = MemSizes::decode(w[1]),
                  .ranges = MemRanges::decode(w[2]),
                  .address_pointer = w[3],
                  .name = text_of(bytes.subspan(8, 8))};
}

Bytes InfoArea::encode() const {
  Bytes out;
  append_le(out, cookie, 2);
  append_le(out, sizes.encode(), 2);
  append_le(out, ranges.encode(), 2);
  append_le(out, address_pointer, 2);
  for (std::size_t i = 0; i < 8; ++i) out.push_back(i < name.size() ? static_cast<Byte>(name[i]) : 0);
  return out;
}

BoardInfo BoardInfo::parse(ByteView bytes) {
  if (bytes.size() < board_info::kBytes)
    throw ProtocolError("LBP16 board info needs " + std::to_string(board_info::kBytes) + " bytes, got " +
                        std::to_string(bytes.size()));
  return BoardInfo{
      .card_name = text_of(bytes.subspan(0, 16)),
      .lbp16_version = static_cast<std::uint16_t>(read_le(bytes.subspan(board_info::kLbpVersion, 2))),
      .firmware_version = static_cast<std::uint16_t>(read_le(bytes.subspan(board_info::kFirmwareVersion, 2))),
      .option_jumpers = static_cast<std::uint16_t>(read_le(bytes.subspan(board_info::kOptionJumpers, 2)))};
}

Command read_board_info() {
  return read(space::kBoardInfo, board_info::kCardName, Width::Bits16, board_info::kBytes / 2, true);
}

std::string text_of(ByteView chars) {
  std::string out;
  for (Byte b : chars) {
    if (b == 0) break;
    out.push_back(static_cast<char>(b));
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

}  // namespace i20::lbp::lbp16
