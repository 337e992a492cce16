// SPDX-License-Identifier: GPL-2.0-or-later
// LBP16: the UDP register protocol of Mesa's Ethernet Anything-I/O cards (7I96S and
// 7I92T manuals, "LBP16 COMMANDS", "INFO AREA", "SUPPORTED MEMORY SPACES").
//
// A command is a 16-bit word, sent LSB first:
//
//   15 14 13 12 11 10  9  8  7  6..0
//    W  A  C  M  M  M  S  S  I  N (count 1..127)
//
// followed by a 16-bit address when A is set and, for writes, count elements of data.
// Several commands may share one UDP packet; the reply packet holds the read data of
// every read command, in order. Writes return nothing. Everything is little endian.
//
// Pure codec: builds request packets, splits reply packets, and parses requests on the
// card side. No sockets here.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lbp/bytes.hpp"

namespace i20::lbp::lbp16 {

inline constexpr std::uint16_t kUdpPort = 27181;
// One UDP payload in a 1500-byte Ethernet frame (no fragmentation: manual,
// "HOST COMMUNICATION"): 1500 - 20 (IPv4) - 8 (UDP).
inline constexpr std::size_t kMaxPayload = 1472;
inline constexpr unsigned kMaxCount = 127;
inline constexpr unsigned kSpaceCount = 8;

// The memory spaces the 7I96S/7I92T firmware implements (space 5 is unused).
namespace space {
inline constexpr std::uint8_t kHostMot2 = 0;
inline constexpr std::uint8_t kEthernetChip = 1;
inline constexpr std::uint8_t kEthernetEeprom = 2;
inline constexpr std::uint8_t kFpgaFlash = 3;
inline constexpr std::uint8_t kTimers = 4;
inline constexpr std::uint8_t kStatus = 6;     // LBP16 R/W: errors, counters, EEPROMWEna
inline constexpr std::uint8_t kBoardInfo = 7;  // LBP16 R/O: card name, versions
}  // namespace space

// Element size, S bits: 00b = 8 bits, 01b = 16, 10b = 32, 11b = 64.
enum class Width : std::uint8_t { Bits8 = 0, Bits16 = 1, Bits32 = 2, Bits64 = 3 };
std::size_t bytes_of(Width width);

struct CommandWord {
  bool write = false;
  bool has_address = false;  // A: a 16-bit address follows and loads the space's pointer
  bool info_area = false;    // C: the space's read-only info area instead of the space
  std::uint8_t space = 0;    // 0..7
  Width width = Width::Bits32;
  bool increment = false;  // I: pointer += element size after every element
  std::uint8_t count = 1;  // 1..127 elements

  std::size_t data_bytes() const { return count * bytes_of(width); }
  // Throws UsageError for a count of 0 or above 127, or a space above 7.
  std::uint16_t encode() const;
  // Throws ProtocolError for a count of 0 (the manual calls it an error).
  static CommandWord decode(std::uint16_t word);

  bool operator==(const CommandWord&) const = default;
};

// One command of a request packet.
struct Command {
  CommandWord word{};
  std::optional<std::uint16_t> address{};  // present exactly when word.has_address
  Bytes data{};                            // write data (count * element bytes), empty for reads

  // Bytes this command adds to the reply packet.
  std::size_t reply_bytes() const { return word.write ? 0 : word.data_bytes(); }
  // Bytes this command occupies in the request packet.
  std::size_t request_bytes() const { return 2 + (address ? 2 : 0) + data.size(); }

  bool operator==(const Command&) const = default;
};

// Reads `count` elements at `address` of `space`. Throws UsageError on a bad count.
Command read(std::uint8_t space, std::uint16_t address, Width width, unsigned count = 1,
             bool increment = true);
// Reads at the space's current address pointer (no address in the command).
Command read_at_pointer(std::uint8_t space, Width width, unsigned count = 1, bool increment = true);
// Writes `data` (a whole number of elements, 1..127 of them) at `address`.
Command write(std::uint8_t space, std::uint16_t address, Width width, ByteView data, bool increment = true);
Command write_at_pointer(std::uint8_t space, Width width, ByteView data, bool increment = true);
// Reads 16-bit words of a space's info area (the only access the info area allows).
Command read_info(std::uint8_t space, std::uint16_t address, unsigned count = 1);

// HostMot2 register conveniences (space 0, 32-bit elements).
Command read_hm2(std::uint16_t address, unsigned count = 1);
Command write_hm2(std::uint16_t address, std::uint32_t value);
Command write_hm2(std::uint16_t address, std::span<const std::uint32_t> values);

// EEPROMWEna (space 6, 0x001A) = 0x5A0N: enables EEPROM/flash writes to space N for the
// rest of the packet only (the card clears it at the end of every packet).
inline constexpr std::uint16_t kEepromWriteEnableAddress = 0x001A;
Command enable_writes(std::uint8_t space);

// Request wire form: the commands back to back. Throws UsageError when the packet or its
// reply would exceed kMaxPayload, or a command is inconsistent (address presence,
// write data length).
Bytes encode(const Command& command);
Bytes encode_packet(std::span<const Command> commands);
std::size_t reply_bytes(std::span<const Command> commands);

// Splits a reply packet into the data of each command (empty for writes). Throws
// ProtocolError when the size differs from what the commands ask for: a reply of the
// wrong size is never acted upon.
std::vector<Bytes> split_reply(std::span<const Command> commands, ByteView reply);

// Card side: cuts a request packet into commands. Stops at a count of 0 or a packet that
// ends inside a command, and says why: the card executes what came before the error.
struct ParseResult {
  std::vector<Command> commands{};
  std::optional<std::string> error{};  // why parsing stopped early
  std::size_t error_offset = 0;
};
ParseResult parse_request(ByteView packet);

// Little-endian element helpers.
std::vector<std::uint16_t> words16(ByteView data);
std::vector<std::uint32_t> words32(ByteView data);
Bytes bytes_of_words(std::span<const std::uint32_t> words);

// ---- Info areas (manual, "INFO AREA") -------------------------------------------------

inline constexpr std::uint16_t kInfoCookieBase = 0x5A00;  // cookie = 0x5A0N for space N
inline constexpr std::size_t kInfoAreaBytes = 16;

// MemSizes: W TTTTTTT XXXX AAAA.
struct MemSizes {
  bool writable = false;
  std::uint8_t type = 0;         // 0x01 register, 0x02 memory, 0x0E EEPROM, 0x0F flash
  std::uint8_t access_mask = 0;  // bit 0 8-bit, bit 1 16-bit, bit 2 32-bit, bit 3 64-bit

  std::uint16_t encode() const;
  static MemSizes decode(std::uint16_t word);
  bool allows(Width width) const { return (access_mask >> static_cast<unsigned>(width)) & 1u; }
  bool operator==(const MemSizes&) const = default;
};
namespace memtype {
inline constexpr std::uint8_t kRegister = 0x01;
inline constexpr std::uint8_t kMemory = 0x02;
inline constexpr std::uint8_t kEeprom = 0x0E;
inline constexpr std::uint8_t kFlash = 0x0F;
}  // namespace memtype

// MemRanges: EEEEE PPPPP SSSSSS, each a power of two in bytes (E and P 0 unless flash).
struct MemRanges {
  std::uint8_t erase_log2 = 0;
  std::uint8_t page_log2 = 0;
  std::uint8_t range_log2 = 0;

  std::uint16_t encode() const;
  static MemRanges decode(std::uint16_t word);
  std::uint64_t range_bytes() const { return std::uint64_t{1} << range_log2; }
  bool operator==(const MemRanges&) const = default;
};

struct InfoArea {
  std::uint16_t cookie = 0;
  MemSizes sizes{};
  MemRanges ranges{};
  std::uint16_t address_pointer = 0;
  std::string name{};  // up to 8 characters, NULs dropped

  bool cookie_ok(std::uint8_t space) const { return cookie == (kInfoCookieBase | space); }
  // From the 16 bytes at info-area address 0. Throws ProtocolError on another size.
  static InfoArea parse(ByteView bytes);
  Bytes encode() const;
};

// ---- Space 7: LBP read-only card information ------------------------------------------

namespace board_info {
inline constexpr std::uint16_t kCardName = 0x0000;  // 16 characters
inline constexpr std::uint16_t kLbpVersion = 0x0010;
inline constexpr std::uint16_t kFirmwareVersion = 0x0012;
inline constexpr std::uint16_t kOptionJumpers = 0x0014;
inline constexpr std::size_t kBytes = 0x0016;  // name + versions + jumpers
}  // namespace board_info

struct BoardInfo {
  std::string card_name{};  // "7I96S": trailing NULs and spaces dropped
  std::uint16_t lbp16_version = 0;
  std::uint16_t firmware_version = 0;
  std::uint16_t option_jumpers = 0;

  // From board_info::kBytes bytes read at space 7 address 0.
  static BoardInfo parse(ByteView bytes);
};

// The command that reads BoardInfo in one go.
Command read_board_info();

// Text of a fixed-size character field: stops at the first NUL, trims trailing spaces.
std::string text_of(ByteView chars);

}  // namespace i20::lbp::lbp16
