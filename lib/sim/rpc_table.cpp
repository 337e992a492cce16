// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/rpc_table.hpp"

#include <algorithm>

#include "lbp/header.hpp"
#include "lbp/rpc.hpp"

namespace i20::sim {
namespace {

lbp::RpcStep step(const RegisterMap& map, const char* name, bool write) {
  return {.header = {.write = write, .has_address = true, .size = lbp::DataSize::Two},
          .address = map.at(name).address};
}

void place(lbp::Bytes& table, unsigned rpc, const std::vector<lbp::RpcStep>& steps) {
  const lbp::Bytes list = lbp::encode_rpc_list(steps);
  std::copy(list.begin(), list.end(),
            table.begin() + static_cast<std::ptrdiff_t>(rpc * lbp::local::kRpcPitch));
}

}  // namespace

lbp::Bytes preloaded_rpc_table(const RegisterMap& map) {
  lbp::Bytes table(kRpcTableBytes, 0x00);
  place(table, 0, {step(map, "ANGLE", true), step(map, "QSETPOINT", true)});
  place(table, 1, {step(map, "BUSV", false), step(map, "TEMPERATURE", false)});
  place(table, 2, {step(map, "FAULT", false), step(map, "STATUS", false)});
  place(table, 3,
        {step(map, "ANGLE", true), step(map, "QSETPOINT", true), step(map, "TEMPERATURE", false),
         step(map, "BUSV", false), step(map, "STATUS", false), step(map, "FAULT", false)});
  return table;
}

}  // namespace i20::sim
