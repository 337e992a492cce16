// SPDX-License-Identifier: GPL-2.0-or-later
#include "link/serial_link.hpp"

namespace i20::link {

std::unique_ptr<PipelinedLink> open_serial_link(const std::string& path, const PipelinedLinkOptions& options,
                                                const SerialOptions& serial) {
  return std::make_unique<PipelinedLink>(std::make_unique<SerialStream>(path, serial), options);
}

}  // namespace i20::link
