// SPDX-License-Identifier: GPL-2.0-or-later
// The usual way to reach an 8I20 in setup mode from a PC: a serial port (USB adapter
// such as the 3I22) at 115200 8N1, with pipelined setup-mode LBP on top.
#pragma once

#include <memory>
#include <string>

#include "link/pipelined_link.hpp"
#include "link/serial_stream.hpp"

namespace i20::link {

// Opens `path` and returns a link over it. Throws LinkError naming the path and the
// likely fix when the port cannot be opened. The result converts to
// std::unique_ptr<Link>; keep the PipelinedLink type for statistics() and notes().
std::unique_ptr<PipelinedLink> open_serial_link(const std::string& path, const PipelinedLinkOptions& options,
                                                const SerialOptions& serial);

}  // namespace i20::link
