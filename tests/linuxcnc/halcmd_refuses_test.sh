#!/bin/bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The statements `i20 hal lint` says halcmd refuses are the ones LinuxCNC's own halcmd
# refuses: tests/linuxcnc/data/halcmd-refuses.hal runs in halrun (-k: every failing command
# is reported as FILE:LINE and halrun goes on), and the lines halcmd names must be exactly
# the lines of the lint's refused findings, which exit 2. Only components that load without
# a card (threads, pid, bldc, and2), so no network namespaces: halrun runs as an unprivileged
# user (nobody when run as root), in an IPC namespace of its own when it can be made, so its
# HAL memory is not another halrun's.
#
# usage: halcmd_refuses_test.sh I20 HALFILE      exit 0 pass, 1 fail, 77 skipped
set -u
I20=${1:?usage: halcmd_refuses_test.sh I20 HALFILE}
FILE=${2:?usage: halcmd_refuses_test.sh I20 HALFILE}
fail() {
  echo "FAIL: $*"
  exit 1
}
command -v halrun >/dev/null || { echo "SKIPPED: LinuxCNC's halrun is not installed (linuxcnc-uspace)" && exit 77; }
for module in threads pid bldc and2; do
  [[ -e /usr/lib/linuxcnc/modules/$module.so ]] || { echo "SKIPPED: LinuxCNC's $module is not installed" && exit 77; }
done
work=$(mktemp -d /tmp/i20-halcmd-refuses.XXXXXX)
chmod 755 "$work"
mkdir "$work/home"
cp "$FILE" "$work/refuses.hal"
chmod 644 "$work/refuses.hal"

# halrun as the HAL user: rtapi_app keeps its socket in $HOME.
as_hal_user=(env HOME="$work/home")
if [[ $EUID -eq 0 ]]; then
  id nobody >/dev/null 2>&1 || { echo "SKIPPED: no user 'nobody' to run halrun as" && exit 77; }
  chown nobody "$work/home"
  as_hal_user=(runuser -u nobody -- env HOME="$work/home")
  unshare --ipc true 2>/dev/null && as_hal_user=(unshare --ipc "${as_hal_user[@]}")
fi
trap 'rm -rf "$work"' EXIT

# 1. The lint: exit 2, and the lines of its refused findings.
"$I20" --json hal lint "$work/refuses.hal" >"$work/lint.json" 2>"$work/lint.err"
status=$?
((status == 2)) || fail "i20 hal lint exited $status, not 2: $(cat "$work/lint.json" "$work/lint.err")"

# 2. halcmd, in halrun.
# In the same namespace: rtapi_app outlives a halrun that timed out; halrun -U stops it.
(cd "$work" && "${as_hal_user[@]}" sh -c 'timeout 60 halrun -k -f "$1"; halrun -U >/dev/null 2>&1' _ \
  "$work/refuses.hal") >"$work/halrun.out" 2>&1
cat "$work/halrun.out"

# 3. The same lines. A second loadrt is refused by rtapi_app ("bldc: already exists": the
# module is not loaded again), which LinuxCNC 2.9's halcmd reports on the line in some runs
# only: for those findings the refusal must be in halrun's output, the line may be.
python3 - "$work/lint.json" "$work/halrun.out" "$work/refuses.hal" <<'PY' || fail "the lint and halcmd disagree"
import json, re, sys
findings = json.load(open(sys.argv[1]))["findings"]
output = open(sys.argv[2]).read()
path = sys.argv[3]
others = [f["rule"] + ":" + str(f["line"]) for f in findings if not f["halcmd_refuses"]]
if others:
    sys.exit("findings that are no refusal: " + ", ".join(others))
halcmd = {int(m) for m in re.findall("^" + re.escape(path) + r":(\d+): ", output, re.M)}
reload_lines = {f["line"] for f in findings if f["rule"] == "module-loaded-twice"}
lint = {f["line"] for f in findings} - reload_lines
print("lint refuses lines:   ", sorted(lint), "and loadrt again at", sorted(reload_lines))
print("halcmd refused lines: ", sorted(halcmd))
if lint != halcmd - reload_lines:
    sys.exit("the lines differ")
for f in findings:
    if f["rule"] == "module-loaded-twice":
        module = f["message"].split()[1].rstrip(":")
        if module + ": already exists" not in output:
            sys.exit(module + " loaded twice, and halrun did not refuse it")
PY
echo "halcmd_refuses_test: passed"
