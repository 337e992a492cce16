// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/virtual_board.hpp"

#include <algorithm>

#include "error/error.hpp"

namespace i20::ethsim {

namespace lbp16 = lbp::lbp16;
namespace hm2 = lbp::hm2;
using lbp16::Width;

namespace {

struct SpaceInfo {
  bool present = false;
  lbp16::MemSizes sizes{};
  lbp16::MemRanges ranges{};
  const char* name = "";
};

SpaceInfo space_info(std::uint8_t space) {
  using namespace lbp16::memtype;
  constexpr std::uint8_t k16 = 0x02, k32 = 0x04;
  switch (space) {
    case lbp16::space::kHostMot2: return {true, {true, kRegister, k32}, {0, 0, 16}, "HostMot2"};
    case lbp16::space::kEthernetChip: return {true, {true, kRegister, k16}, {0, 0, 8}, "KSZ8851"};
    case lbp16::space::kEthernetEeprom: return {true, {true, kEeprom, k16}, {0, 0, 7}, "EEPROM"};
    case lbp16::space::kFpgaFlash: return {true, {true, kFlash, k32}, {16, 8, 21}, "SPIFlash"};
    case lbp16::space::kTimers: return {true, {true, kRegister, k16}, {0, 0, 5}, "Timers"};
    case lbp16::space::kStatus: return {true, {true, kRegister, k16}, {0, 0, 5}, "LBP16RW"};
    case lbp16::space::kBoardInfo: return {true, {false, kRegister, k16}, {0, 0, 5}, "LBP16RO"};
    default: return {};
  }
}

// Characters packed two per 16-bit word, first character in the low byte.
void put_text(std::vector<std::uint16_t>& words, std::size_t first_word, const std::string& text,
              std::size_t chars) {
  for (std::size_t i = 0; i < chars; i += 2) {
    const auto lo = static_cast<std::uint8_t>(i < text.size() ? text[i] : 0);
    const auto hi = static_cast<std::uint8_t>(i + 1 < text.size() ? text[i + 1] : 0);
    words[first_word + i / 2] = static_cast<std::uint16_t>(lo | hi << 8);
  }
}

// Space 1: the KSZ8851's chip ID and enable register (CIDER).
constexpr std::uint16_t kCiderAddress = 0x00C0;
constexpr std::uint16_t kKsz8851ChipId = 0x8872;

// Space 3 registers.
constexpr std::uint16_t kFlashAddress = 0x0000;
constexpr std::uint16_t kFlashData = 0x0004;
constexpr std::uint16_t kFlashId = 0x0008;
constexpr std::uint16_t kFlashSectorErase = 0x000C;
constexpr std::uint32_t kFlashBytes = 2u << 20;
constexpr std::uint32_t kFlashSector = 0x10000;

// Space 4 registers.
constexpr std::uint16_t kTimeStamp = 0x0000;
constexpr std::uint16_t kWaitMicroseconds = 0x0002;

// Ethernet EEPROM: the first 0x20 bytes are read only.
constexpr std::uint16_t kEepromWritableFrom = 0x0020;

}  // namespace

VirtualBoard::VirtualBoard(VirtualBoardOptions options, Clock::time_point now)
    : config_(std::move(options.config)), feedback_(config_, now), start_(now), now_(now) {
  const auto store = [this](std::uint32_t address, const lbp::Bytes& bytes) {
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      std::uint32_t& w = hm2_.at((address + i) / 4);
      const unsigned shift = 8 * ((address + i) % 4);
      w = (w & ~(0xFFu << shift)) | (std::uint32_t{bytes[i]} << shift);
    }
  };
  store(hm2::kCookieAddress,
        hm2::IdentArea{
            .cookie = hm2::kCookie, .config_name = hm2::kConfigName, .idrom_address = config_.idrom_address}
            .encode());
  store(config_.idrom_address, config_.idrom.encode());
  for (std::size_t i = 0; i < config_.modules.size(); ++i)
    store(config_.idrom_address + config_.idrom.offset_to_modules + i * hm2::ModuleDescriptor::kBytes,
          config_.modules[i].encode());
  for (std::size_t i = 0; i < config_.pins.size(); ++i)
    store(config_.idrom_address + config_.idrom.offset_to_pins + i * hm2::PinDescriptor::kBytes,
          config_.pins[i].encode());
  idrom_end_ = static_cast<std::uint16_t>(config_.idrom_address + config_.idrom.offset_to_pins +
                                          config_.pins.size() * hm2::PinDescriptor::kBytes);

  eth_chip_[kCiderAddress / 2] = kKsz8851ChipId;
  const auto& mac = config_.mac;
  eeprom_[1] = static_cast<std::uint16_t>(mac[4] << 8 | mac[5]);
  eeprom_[2] = static_cast<std::uint16_t>(mac[2] << 8 | mac[3]);
  eeprom_[3] = static_cast<std::uint16_t>(mac[0] << 8 | mac[1]);
  put_text(eeprom_, 0x10 / 2, config_.card_name, 16);
  eeprom_[0x20 / 2] = static_cast<std::uint16_t>(config_.eeprom_ip);
  eeprom_[0x22 / 2] = static_cast<std::uint16_t>(config_.eeprom_ip >> 16);
  eeprom_[0x24 / 2] = static_cast<std::uint16_t>(config_.eeprom_netmask);
  eeprom_[0x26 / 2] = static_cast<std::uint16_t>(config_.eeprom_netmask >> 16);

  put_text(info_, 0, config_.card_name, 16);
  info_[lbp16::board_info::kLbpVersion / 2] = config_.lbp16_version;
  info_[lbp16::board_info::kFirmwareVersion / 2] = config_.firmware_version;
  info_[lbp16::board_info::kOptionJumpers / 2] = config_.option_jumpers;

  for (unsigned port = 0; port < config_.sserial_ports; ++port) {
    SslbpConfig sslbp = options.sslbp;
    sslbp.channels = config_.channels_per_port;
    std::vector<std::unique_ptr<RemoteLbpDevice>> remotes(sslbp.channels);
    if (options.remotes)
      for (unsigned ch = 0; ch < sslbp.channels; ++ch) remotes[ch] = options.remotes(port, ch);
    ports_.push_back(std::make_unique<SslbpEngine>(sslbp, std::move(remotes), now));
  }
}

void VirtualBoard::advance(Clock::time_point now) {
  now_ = std::max(now_, now);
  for (auto& port : ports_) port->advance(now_);
  feedback_.advance(now_);
}

std::optional<lbp::Bytes> VirtualBoard::handle(lbp::ByteView request, Clock::time_point now) {
  advance(now);
  ++stats_.packets;
  ++status_[status_reg::kRxPackets / 2];
  ++status_[status_reg::kRxUdp / 2];
  const lbp16::ParseResult parsed = lbp16::parse_request(request);
  lbp::Bytes reply;
  for (const auto& command : parsed.commands) execute(command, reply);
  if (parsed.error) {
    ++stats_.parse_errors;
    ++status_[status_reg::kParseErrors / 2];
    status_[status_reg::kErrors / 2] |= status_reg::kParseErrorBit;
  }
  // "EEPROMWEna is cleared at the end of every LBP packet."
  status_[status_reg::kEepromWriteEnable / 2] = 0;
  if (reply.empty()) return std::nullopt;
  ++stats_.replies;
  ++status_[status_reg::kTxPackets / 2];
  ++status_[status_reg::kTxUdp / 2];
  return reply;
}

void VirtualBoard::execute(const lbp16::Command& command, lbp::Bytes& reply) {
  const auto& word = command.word;
  const std::uint8_t space = word.space;
  std::uint16_t& pointer = word.info_area ? info_pointer_[space] : pointer_[space];
  if (command.address) pointer = *command.address;
  const std::size_t n = lbp16::bytes_of(word.width);
  const bool allowed = width_allowed(space, word.width, word.info_area);
  if (!allowed) mem_error();
  if (word.write && word.info_area) write_error();
  for (unsigned i = 0; i < word.count; ++i) {
    if (!word.write) {
      const std::uint64_t value = allowed ? read_element(space, pointer, word.width, word.info_area) : 0;
      lbp::append_le(reply, value, n);
    } else if (allowed && !word.info_area) {
      write_element(space, pointer, word.width, lbp::read_le(lbp::ByteView(command.data).subspan(i * n, n)));
    }
    if (word.increment) pointer = static_cast<std::uint16_t>(pointer + n);
  }
}

bool VirtualBoard::width_allowed(std::uint8_t space, Width width, bool info) const {
  const SpaceInfo s = space_info(space);
  if (!s.present) return false;
  if (info) return width == Width::Bits16;
  return s.sizes.allows(width);
}

lbp16::InfoArea VirtualBoard::info_area(std::uint8_t space) const {
  const SpaceInfo s = space_info(space);
  return lbp16::InfoArea{.cookie = static_cast<std::uint16_t>(lbp16::kInfoCookieBase | space),
                         .sizes = s.sizes,
                         .ranges = s.ranges,
                         .address_pointer = pointer_[space],
                         .name = s.name};
}

std::uint64_t VirtualBoard::read_element(std::uint8_t space, std::uint16_t address, Width width, bool info) {
  const std::size_t n = lbp16::bytes_of(width);
  if (address % n != 0) {
    mem_error();
    return 0;
  }
  if (info) {
    if (address >= lbp16::kInfoAreaBytes) {
      mem_error();
      return 0;
    }
    return lbp::read_le(lbp::ByteView(info_area(space).encode()).subspan(address, 2));
  }
  const auto word16 = [&](const std::vector<std::uint16_t>& words) -> std::uint64_t {
    if (address / 2 >= words.size()) {
      mem_error();
      return 0;
    }
    return words[address / 2];
  };
  switch (space) {
    case lbp16::space::kHostMot2: return hm2_read(address);
    case lbp16::space::kEthernetChip: return word16(eth_chip_);
    case lbp16::space::kEthernetEeprom: return word16(eeprom_);
    case lbp16::space::kFpgaFlash: return flash_read(address);
    case lbp16::space::kTimers:
      if (address == kTimeStamp)
        return static_cast<std::uint16_t>(
            std::chrono::duration_cast<std::chrono::microseconds>(now_ - start_).count());
      return word16(timers_);
    case lbp16::space::kStatus: return word16(status_);
    case lbp16::space::kBoardInfo: return word16(info_);
    default: mem_error(); return 0;
  }
}

void VirtualBoard::write_element(std::uint8_t space, std::uint16_t address, Width width,
                                 std::uint64_t value) {
  const std::size_t n = lbp16::bytes_of(width);
  if (address % n != 0) return mem_error();
  const auto put16 = [&](std::vector<std::uint16_t>& words) {
    if (address / 2 >= words.size()) return mem_error();
    words[address / 2] = static_cast<std::uint16_t>(value);
  };
  switch (space) {
    case lbp16::space::kHostMot2: return hm2_write(address, static_cast<std::uint32_t>(value));
    case lbp16::space::kEthernetChip: return put16(eth_chip_);
    case lbp16::space::kEthernetEeprom:
      if (address < kEepromWritableFrom || status_[status_reg::kEepromWriteEnable / 2] !=
                                               (lbp16::kInfoCookieBase | lbp16::space::kEthernetEeprom))
        return write_error();
      return put16(eeprom_);
    case lbp16::space::kFpgaFlash: return flash_write(address, static_cast<std::uint32_t>(value));
    case lbp16::space::kTimers:
      if (address == kTimeStamp) return;  // "writes to the uSTimeStamp register are a no-op"
      if (address == kWaitMicroseconds) now_ += std::chrono::microseconds(value & 0xFFFF);
      return put16(timers_);
    case lbp16::space::kStatus: return put16(status_);
    default: return write_error();  // space 7 is read only; space 5 does not exist
  }
}

std::optional<VirtualBoard::SserialTarget> VirtualBoard::sserial_at(std::uint16_t address) const {
  const hm2::ModuleDescriptor& m = config_.sserial_module();
  const std::uint32_t reg_stride = m.register_stride(config_.idrom);
  const std::uint32_t instance_stride = m.instance_stride(config_.idrom);
  if (address < m.base_address) return std::nullopt;
  const std::uint32_t offset = address - m.base_address;
  const unsigned reg = offset / reg_stride;
  if (reg >= m.registers) return std::nullopt;
  const std::uint32_t within = offset % reg_stride;
  const unsigned port = within / instance_stride;
  const unsigned channel = (within % instance_stride) / 4;
  if (port >= ports_.size()) return std::nullopt;
  if ((reg == hm2::sserial_reg::kCommand || reg == hm2::sserial_reg::kData) && channel != 0)
    return std::nullopt;
  return SserialTarget{port, reg, channel};
}

bool VirtualBoard::hm2_read_only(std::uint16_t address) const {
  const bool ident = address >= hm2::kCookieAddress && address < hm2::kCookieAddress + 16;
  const bool idrom = address >= config_.idrom_address && address < idrom_end_;
  return ident || idrom;
}

std::uint32_t VirtualBoard::hm2_read(std::uint16_t address) {
  if (address % 4 != 0) {
    mem_error();
    return 0;
  }
  if (const auto s = sserial_at(address)) return ports_[s->port]->read(s->reg, s->channel, now_);
  if (const auto value = feedback_.read(address, now_)) return *value;
  return hm2_[address / 4];
}

void VirtualBoard::hm2_write(std::uint16_t address, std::uint32_t value) {
  if (hm2_read_only(address)) return write_error();
  if (const auto s = sserial_at(address)) return ports_[s->port]->write(s->reg, s->channel, value, now_);
  hm2_[address / 4] = value;
  feedback_.write(address, value, now_);
}

std::uint32_t VirtualBoard::flash_read(std::uint16_t address) {
  switch (address) {
    case kFlashAddress: return flash_address_;
    case kFlashId: return config_.flash_id;
    case kFlashData: {
      const auto it = flash_.find(flash_address_);
      const std::uint32_t value = it == flash_.end() ? 0xFFFFFFFF : it->second;
      flash_address_ = (flash_address_ + 4) % kFlashBytes;
      return value;
    }
    default: mem_error(); return 0;
  }
}

void VirtualBoard::flash_write(std::uint16_t address, std::uint32_t value) {
  const bool enabled =
      status_[status_reg::kEepromWriteEnable / 2] == (lbp16::kInfoCookieBase | lbp16::space::kFpgaFlash);
  switch (address) {
    case kFlashAddress: flash_address_ = value % kFlashBytes; return;
    case kFlashData:
      if (!enabled) return write_error();
      flash_[flash_address_] = value;
      flash_address_ = (flash_address_ + 4) % kFlashBytes;
      return;
    case kFlashSectorErase: {
      if (!enabled) return write_error();
      const std::uint32_t sector = flash_address_ & ~(kFlashSector - 1);
      flash_.erase(flash_.lower_bound(sector), flash_.lower_bound(sector + kFlashSector));
      return;
    }
    default: return write_error();
  }
}

void VirtualBoard::mem_error() {
  ++stats_.mem_errors;
  ++status_[status_reg::kMemErrors / 2];
  status_[status_reg::kErrors / 2] |= status_reg::kMemErrorBit;
}

void VirtualBoard::write_error() {
  ++stats_.write_errors;
  ++status_[status_reg::kWriteErrors / 2];
  status_[status_reg::kErrors / 2] |= status_reg::kWriteErrorBit;
}

std::uint16_t VirtualBoard::status_register(std::uint16_t address) const {
  return status_.at(address / 2);
}

std::uint16_t VirtualBoard::eeprom_word(std::uint16_t address) const {
  return eeprom_.at(address / 2);
}

}  // namespace i20::ethsim
