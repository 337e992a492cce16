# shellcheck shell=bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The LinuxCNC tests' rig is the product's own (apps/halrun-virtual/rig.sh, which
# `i20 hal lint --load` runs): one rig, so what the tests prove is what users get.
# shellcheck source=../../apps/halrun-virtual/rig.sh
source "$(dirname "${BASH_SOURCE[0]}")/../../apps/halrun-virtual/rig.sh"
