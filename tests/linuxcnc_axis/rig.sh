# shellcheck shell=bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The LinuxCNC tests' rig is the product's own (apps/halrun-virtual/rig.sh, which
# `i20 hal lint --load` runs): one rig, so what the tests prove is what users get.
# shellcheck source=../../apps/halrun-virtual/rig.sh
source "$(dirname "${BASH_SOURCE[0]}")/../../apps/halrun-virtual/rig.sh"

# The last reading NAME from halrun's output ($work/hal.out): a label prints "NAME=" and
# halcmd's getp/gets the value after it. hostmot2 prints its own lines into the same
# output ("error finishing read" on a loaded host), and one can land between the two, which
# leaves "NAME=hm2/..." and the value on the next line: take the first value-shaped line then.
value() {
  awk -v key="$1=" '
    function reading(s) { return s ~ /^-?[0-9]+(\.[0-9]*)?([eE][-+]?[0-9]+)?$/ || s == "TRUE" || s == "FALSE" }
    pending && reading($0) { last = $0; pending = 0; next }
    index($0, key) == 1 {
      rest = substr($0, length(key) + 1)
      if (reading(rest)) { last = rest; pending = 0 } else pending = 1
    }
    END { print last }' "$work/hal.out"
}
