// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/passthrough_plan.hpp"

#include "lbp/header.hpp"
#include "hostmot2/hostmot2.hpp"
#include "lbp/local.hpp"
#include "link/link.hpp"

namespace i20::eth {
namespace {

[[noreturn]] void refuse(const lbp::Command& command, const std::string& why) {
  throw link::UnsupportedCommand("SSLBP passthrough cannot carry LBP command " + lbp::to_hex(command.bytes) +
                                 ": " + why);
}

void require_length(const lbp::Command& command, std::size_t expected) {
  if (command.bytes.size() != expected)
    refuse(command, "it is " + std::to_string(command.bytes.size()) + " bytes long, its header says " +
                        std::to_string(expected));
}

PassthroughStep plan_data(const lbp::Command& command) {
  const lbp::DataHeader h = lbp::DataHeader::decode(command.bytes[0]);
  if (!h.has_address) refuse(command, "it has no address (SSLBP always sends the address from CS)");
  if (h.rpc_includes_data) refuse(command, "its data comes from a stored RPC (RID bit)");
  const std::size_t n = h.data_bytes();
  if (n > 4)
    refuse(command,
           "8-byte data does not fit the 32-bit INTERFACE0 register; split it into two 4-byte accesses");
  require_length(command, 3 + (h.write ? n : 0));
  const auto address = static_cast<std::uint16_t>(lbp::read_le(lbp::ByteView(command.bytes).subspan(1, 2)));
  PassthroughStep step{.cs = lbp::hm2::sslbp::passthrough_cs(command.bytes[0], address)};
  step.data_bytes = n;
  if (h.write) {
    step.interface0 = static_cast<std::uint32_t>(lbp::read_le(lbp::ByteView(command.bytes).subspan(3, n)));
    step.data_write = true;
    step.effect = StepEffect::DataWrite;
  } else {
    step.reply_bytes = n;
  }
  step.wire_bytes = command.bytes.size() + 1 + step.reply_bytes + 1;
  return step;
}

PassthroughStep plan_local(const lbp::Command& command) {
  const lbp::Byte header = command.bytes[0];
  PassthroughStep step{.cs = lbp::hm2::sslbp::passthrough_cs(header, 0)};
  if (lbp::kind_of(header) == lbp::CommandKind::LocalRead) {
    require_length(command, 1);
    step.reply_bytes = 1;
  } else {
    if (header == lbp::local::kResetParser)
      refuse(command, "0xFF has no data byte and SSLBP always sends one");
    require_length(command, 2);
    step.interface0 = command.bytes[1];
    step.repeatable = header != lbp::local::kAddToAddress && header != lbp::local::kResetProcessor;
    step.effect = step.repeatable ? StepEffect::LocalWrite : StepEffect::Unrepeatable;
    if (header == lbp::local::kSetNvAccess) {
      step.nv_access_mode = command.bytes[1];
      step.effect = StepEffect::NvMode;
    }
  }
  step.wire_bytes = command.bytes.size() + 1 + step.reply_bytes + 1;
  return step;
}

}  // namespace

PassthroughStep plan_passthrough(const lbp::Command& command) {
  if (command.bytes.empty()) refuse(command, "it is empty");
  switch (lbp::kind_of(command.bytes[0])) {
    case lbp::CommandKind::Data: return plan_data(command);
    case lbp::CommandKind::LocalRead:
    case lbp::CommandKind::LocalWrite: return plan_local(command);
    case lbp::CommandKind::Rpc:
      refuse(command, "RPCs are not passed through (their length is in the 8I20's RPC table)");
    default: refuse(command, "header 0x00..0x3F is not an LBP command");
  }
}

lbp::Bytes reply_from_interface0(std::uint32_t interface0, std::size_t reply_bytes) {
  return lbp::to_le(interface0, reply_bytes);
}

}  // namespace i20::eth
