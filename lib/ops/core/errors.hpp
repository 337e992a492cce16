// SPDX-License-Identifier: GPL-2.0-or-later
// The errors a use case may end in, and the options of a write, as the apps name them: the
// device layer defines them next to the rules that raise them; the apps reach them through
// lib/ops, so no app includes lib/device. ops::exit_code maps each error's kind.
#pragma once

#include "device/amp.hpp"
#include "device/errors.hpp"
#include "link/link.hpp"

namespace i20::ops {

using device::AmpStateError;   // a mode the card may be left in (NV access, RPC memory)
using device::Cancelled;       // a stop signal, after the card was left in a known state
using device::SafetyError;     // a write the rules refuse; nothing was sent
using device::VerifyError;     // the card accepted a write but reads back something else
using link::LinkError;         // the line failed: no answer, a garbled or foreign reply

using device::check_offline;  // the rules that need no card, before the link opens
using device::WriteOptions;   // --allow-unverified, --force

}  // namespace i20::ops
