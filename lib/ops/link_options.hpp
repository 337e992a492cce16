// SPDX-License-Identifier: GPL-2.0-or-later
// The options of the links under ops, built here and nowhere else (open_link, the fleet's
// Ethernet ports) from the link settings and the retry budget (retry.hpp). ops owns the
// loop for the exchanges it starts, so the links send each of them once: no serial
// retries, no passthrough packet resent after a lost reply. The Ethernet layers' own
// exchanges, which ops never sees (SSLBP commands while a port opens, read-only probes and
// polls of SSLBP's registers, IDROM reads), get the budget instead: at most
// `retry.attempts` sends each, and only where LBP16 makes a resend safe.
#pragma once

#include <memory>

#include "link/link.hpp"
#include "link/pipelined_link.hpp"
#include "ops/endpoint.hpp"
#include "ops/retry.hpp"
#include "params/param_db.hpp"

namespace i20::eth {
struct PassthroughOptions;
}

namespace i20::ops {

link::PipelinedLinkOptions serial_link_options(const LinkSettings& settings, const RetryPolicy& retry);
eth::PassthroughOptions passthrough_options(const LinkSettings& settings, const RetryPolicy& retry);

// open_link (endpoint.hpp) with the links' options built from `retry`, the budget of the
// ops::Amp that will own the link.
std::unique_ptr<link::Link> open_link(const Endpoint& endpoint, const params::ParamDb& db,
                                      const LinkSettings& settings, const RetryPolicy& retry);

}  // namespace i20::ops
