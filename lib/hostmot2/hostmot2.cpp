// SPDX-License-Identifier: GPL-2.0-or-later
#include "hostmot2/hostmot2.hpp"

#include "lbp/bytes.hpp"
#include "lbp/error.hpp"
#include "lbp16/lbp16.hpp"

namespace i20::lbp::hm2 {
namespace {

std::uint32_t word_at(ByteView bytes, std::size_t index) {
  return static_cast<std::uint32_t>(read_le(bytes.subspan(4 * index, 4)));
}

void require_size(ByteView bytes, std::size_t size, const char* what) {
  if (bytes.size() != size)
    throw ProtocolError(std::string(what) + " is " + std::to_string(size) + " bytes, got " +
                        std::to_string(bytes.size()));
}

void append_text(Bytes& out, const std::string& text, std::size_t size) {
  for (std::size_t i = 0; i < size; ++i) out.push_back(i < text.size() ? static_cast<Byte>(text[i]) : 0);
}

}  // namespace

IdentArea IdentArea::parse(ByteView bytes) {
  require_size(bytes, 16, "the HostMot2 identification area");
  return IdentArea{.cookie = word_at(bytes, 0),
                   .config_name = lbp16::text_of(bytes.subspan(4, 8)),
                   .idrom_address = word_at(bytes, 3)};
}

Bytes IdentArea::encode() const {
  Bytes out;
  append_le(out, cookie, 4);
  append_text(out, config_name, 8);
  append_le(out, idrom_address, 4);
  return out;
}

Idrom Idrom::parse(ByteView bytes) {
  require_size(bytes, kBytes, "a HostMot2 IDROM");
  Idrom r;
  r.type = word_at(bytes, 0);
  r.offset_to_modules = word_at(bytes, 1);
  r.offset_to_pins = word_at(bytes, 2);
  r.board_name = lbp16::text_of(bytes.subspan(12, 8));
  r.fpga_size = word_at(bytes, 5);
  r.fpga_pins = word_at(bytes, 6);
  r.io_ports = word_at(bytes, 7);
  r.io_width = word_at(bytes, 8);
  r.port_width = word_at(bytes, 9);
  r.clock_low = word_at(bytes, 10);
  r.clock_high = word_at(bytes, 11);
  r.instance_stride0 = word_at(bytes, 12);
  r.instance_stride1 = word_at(bytes, 13);
  r.register_stride0 = word_at(bytes, 14);
  r.register_stride1 = word_at(bytes, 15);
  return r;
}

Bytes Idrom::encode() const {
  Bytes out;
  for (std::uint32_t w : {type, offset_to_modules, offset_to_pins}) append_le(out, w, 4);
  append_text(out, board_name, 8);
  for (std::uint32_t w : {fpga_size, fpga_pins, io_ports, io_width, port_width, clock_low, clock_high,
                          instance_stride0, instance_stride1, register_stride0, register_stride1})
    append_le(out, w, 4);
  return out;
}

bool is_sserial(std::uint8_t tag) {
  return tag == gtag::kSserial || tag == gtag::kSserialB;
}

ModuleDescriptor ModuleDescriptor::parse(ByteView bytes) {
  require_size(bytes, kBytes, "a HostMot2 module descriptor");
  return ModuleDescriptor{.gtag = bytes[0],
                          .version = bytes[1],
                          .clock_tag = bytes[2],
                          .instances = bytes[3],
                          .base_address = static_cast<std::uint16_t>(read_le(bytes.subspan(4, 2))),
                          .registers = bytes[6],
                          .strides = bytes[7],
                          .multiple_registers = word_at(bytes, 2)};
}

Bytes ModuleDescriptor::encode() const {
  Bytes out{gtag, version, clock_tag, instances};
  append_le(out, base_address, 2);
  out.push_back(registers);
  out.push_back(strides);
  append_le(out, multiple_registers, 4);
  return out;
}

std::uint32_t ModuleDescriptor::register_stride(const Idrom& idrom) const {
  return (strides & 0x0F) == 0 ? idrom.register_stride0 : idrom.register_stride1;
}

std::uint32_t ModuleDescriptor::instance_stride(const Idrom& idrom) const {
  return (strides & 0xF0) == 0 ? idrom.instance_stride0 : idrom.instance_stride1;
}

std::uint16_t ModuleDescriptor::register_address(const Idrom& idrom, unsigned reg, unsigned instance) const {
  if (instance >= instances)
    throw UsageError("module " + lbp::hex_value(gtag, 2) + " has " + std::to_string(instances) +
                     " instance(s), there is no instance " + std::to_string(instance));
  if (reg >= registers)
    throw UsageError("module has " + std::to_string(registers) + " registers, there is no register " +
                     std::to_string(reg));
  const std::uint64_t address = std::uint64_t{base_address} + std::uint64_t{reg} * register_stride(idrom) +
                                std::uint64_t{instance} * instance_stride(idrom);
  if (address > 0xFFFC)
    throw UsageError("module register address " + std::to_string(address) + " is outside space 0");
  return static_cast<std::uint16_t>(address);
}

std::optional<ModuleDescriptor::Slot> ModuleDescriptor::slot_at(const Idrom& idrom,
                                                                std::uint16_t address) const {
  const std::uint32_t reg_stride = register_stride(idrom);
  const std::uint32_t inst_stride = instance_stride(idrom);
  if (address < base_address || reg_stride == 0 || inst_stride == 0) return std::nullopt;
  const std::uint32_t offset = address - base_address;
  const unsigned reg = offset / reg_stride;
  const std::uint32_t within = offset % reg_stride;
  if (reg >= registers || within % inst_stride != 0) return std::nullopt;
  const unsigned instance = within / inst_stride;
  const bool per_instance = reg < 32 && (multiple_registers >> reg & 1u) != 0;
  if (instance >= (per_instance ? instances : 1u)) return std::nullopt;
  return Slot{reg, instance};
}

std::vector<ModuleDescriptor> parse_modules(ByteView bytes) {
  std::vector<ModuleDescriptor> out;
  for (std::size_t at = 0; at + ModuleDescriptor::kBytes <= bytes.size() && out.size() < kMaxModules;
       at += ModuleDescriptor::kBytes) {
    const auto m = ModuleDescriptor::parse(bytes.subspan(at, ModuleDescriptor::kBytes));
    if (m.gtag == gtag::kNone) break;
    out.push_back(m);
  }
  return out;
}

PinDescriptor PinDescriptor::parse(ByteView bytes) {
  require_size(bytes, kBytes, "a HostMot2 pin descriptor");
  return PinDescriptor{.secondary_pin = bytes[0],
                       .secondary_tag = bytes[1],
                       .secondary_unit = bytes[2],
                       .primary_tag = bytes[3]};
}

Bytes PinDescriptor::encode() const {
  return Bytes{secondary_pin, secondary_tag, secondary_unit, primary_tag};
}

std::vector<PinDescriptor> parse_pins(ByteView bytes, std::size_t count) {
  if (bytes.size() < count * PinDescriptor::kBytes)
    throw ProtocolError("pin descriptors: " + std::to_string(count) + " pins need " +
                        std::to_string(count * PinDescriptor::kBytes) + " bytes, got " +
                        std::to_string(bytes.size()));
  std::vector<PinDescriptor> out;
  for (std::size_t i = 0; i < count; ++i) out.push_back(PinDescriptor::parse(bytes.subspan(i * 4, 4)));
  return out;
}

SserialRegisters SserialRegisters::locate(const Idrom& idrom, const ModuleDescriptor& module,
                                          unsigned instance) {
  if (!is_sserial(module.gtag))
    throw UsageError("module " + lbp::hex_value(module.gtag, 8) + " is not an SSERIAL module");
  if (module.registers < sserial_reg::kCount)
    throw UsageError("SSERIAL module lists " + std::to_string(module.registers) + " registers, SSLBP needs " +
                     std::to_string(sserial_reg::kCount));
  const auto at = [&](unsigned reg) { return module.register_address(idrom, reg, instance); };
  return SserialRegisters{.command = at(sserial_reg::kCommand),
                          .data = at(sserial_reg::kData),
                          .cs0 = at(sserial_reg::kCs),
                          .interface0_0 = at(sserial_reg::kInterface0),
                          .interface1_0 = at(sserial_reg::kInterface1),
                          .interface2_0 = at(sserial_reg::kInterface2)};
}

namespace sslbp {

std::string ChannelStatus::describe() const {
  std::string out;
  const auto add = [&](bool set, const char* what) {
    if (!set) return;
    if (!out.empty()) out += ", ";
    out += what;
  };
  add(status() & kNotReady, "communication not ready");
  add(status() & kNoRemoteId, "no remote ID");
  add(status() & kCommunicationError, "communication error");
  add(status() & kRemoteFault, "remote fault");
  add(errors() & kTooManyErrors, "too many errors");
  add(errors() & kExtraCharacter, "extra character");
  add(errors() & kTimeoutError, "timeout");
  add(errors() & kOverrun, "overrun");
  add(errors() & kInvalidCookie, "invalid cookie");
  add(errors() & kCrcError, "CRC error");
  return out.empty() ? "ok" : out;
}

std::string name_of_word(std::uint32_t word) {
  std::string out;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((word >> (8 * i)) & 0xFF);
    if (c != 0) out.push_back(c);
  }
  return out;
}

}  // namespace sslbp

}  // namespace i20::lbp::hm2
