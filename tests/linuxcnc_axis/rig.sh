# shellcheck shell=bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The LinuxCNC tests' rig is the product's own (apps/halrun-virtual/rig.sh, which
# `i20 hal lint --load` runs): one rig, so what the tests prove is what users get.
# shellcheck source=../../apps/halrun-virtual/rig.sh
source "$(dirname "${BASH_SOURCE[0]}")/../../apps/halrun-virtual/rig.sh"

# Scripts halrun runs between its own lines, as the HAL user (loadusr -w $work/NAME ...):
#   label NAME          prints "NAME=" (the next getp prints the value: see report, value)
#   until PIN VALUE N   waits, polling halcmd every 0.1 s up to N times, until PIN reads VALUE
#   inject LINE...      one control line to the virtual card (its answer goes to its log)
#   stall SECONDS       stops LinuxCNC's realtime process (its servo thread) that long
#   dump FILE           writes every sample halsampler's sampler.0 holds to FILE
cat >"$work/label" <<'SH'
#!/bin/sh
printf "%s=" "$1"
SH
cat >"$work/until" <<'SH'
#!/bin/sh
i=0
while [ "$i" -lt "$3" ] && [ "$(halcmd getp "$1")" != "$2" ]; do
  sleep 0.1
  i=$((i + 1))
done
SH
cat >"$work/inject" <<SH
#!/bin/sh
echo "\$*" > $work/ctl
SH
cat >"$work/stall" <<'SH'
#!/bin/sh
pkill -STOP -x rtapi_app
sleep "$1"
pkill -CONT -x rtapi_app
SH
cat >"$work/dump" <<'SH'
#!/bin/sh
n=$(halcmd getp sampler.0.curr-depth)
halsampler -c 0 -n "$n" "$1"
SH
chmod 755 "$work/label" "$work/until" "$work/inject" "$work/stall" "$work/dump"
# report NAME PIN: the halrun lines that print the pin's or parameter's value as "NAME=value".
report() { printf 'loadusr -w %s %s\ngetp %s\n' "$work/label" "$1" "$2"; }

# value NAME [FILE]: the last reading NAME from halrun's output (FILE, by default $work/hal.out): a label prints "NAME=" and
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
    END { print last }' "${2:-$work/hal.out}"
}

# The 8I20 turns its output off when no command reaches it for 40 ms (its watchdog, set by
# the normal start: manual, "8I20 DEVICE SPECIFIC SETUP"). halrun's servo thread here is not
# realtime: on a loaded host one period can stretch past that (CI saw 107 ms), and the 8I20
# then rightly stops the motor. Such a run measured the host, not the axis, so each HAL run
# reports its longest period (timedelta.0.max as "period_max") and a stalled one is run
# again, up to STALL_TRIES times in all; the checks judge only a run that kept time.
# A servo period is not the gap the card sees: its watchdog counts from one command's arrival
# to the next, which adds the packet's wait in the card's own (equally unrealtime) process, and
# timedelta cannot see that wait (CI once saw the watchdog bite after a longest period of
# 37.5 ms). So a servo period past half the watchdog (20 ms, twenty periods late) is a stall;
# a gap the tool measured itself at the card's side is judged against the watchdog alone.
WATCHDOG_NS=${I20_TEST_WATCHDOG_NS:-40000000} # a smaller value exercises the re-runs
STALL_NS=$((WATCHDOG_NS / 2))
# Five: on a VM host whose idle 1 ms sleeps overshoot by up to 15 ms, CI's sanitizer run once
# saw i20 commission starved past the watchdog three runs in a row (43, 126 and 55 ms gaps).
STALL_TRIES=5
# After a run: false (run it again) if its longest period, LONGEST_NS (by default the HAL run's
# period_max), outlasted LIMIT_NS (by default STALL_NS) and tries remain; a stalled last try fails.
kept_time() {
  local label=$1 try=$2 longest=${3:-$(value period_max)} limit=${4:-$STALL_NS}
  [[ $longest =~ ^[0-9]+$ ]] && ((longest > limit)) || return 0
  local ms=$((longest / 1000000)) limit_ms=$((limit / 1000000)) watchdog_ms=$((WATCHDOG_NS / 1000000))
  local past="past $limit_ms ms (the 8I20's watchdog is $watchdog_ms ms)"
  ((try < STALL_TRIES)) || fail "$label: a period $past in all $STALL_TRIES runs (last: $ms ms); this host cannot run the test"
  note "$label: a period of $ms ms, $past: the run measured this host, not the axis; running it again ($try of $STALL_TRIES)"
  return 1
}

# judged LABEL TRY WHY [LONGEST_NS [LIMIT_NS]]: run TRY's checks found WHY (empty: they all
# passed). A pass stands whatever the host did (a stall makes a run fail, never pass); a
# failure in a run that stalled (kept_time) is run again while tries remain (returns 1); a
# failure in a run that kept time fails the test.
judged() {
  local label=$1 try=$2 why=$3
  [[ -z $why ]] && return 0
  note "$label: $why"
  kept_time "$label" "$try" "${@:4}" && fail "$label: $why"
  return 1
}

# realtime_started LABEL TRY: false (run it again) when LinuxCNC's realtime did not start in
# the last halrun ($work/hal.out): hm2_eth gave up on the virtual card before any HAL ran
# (its MAC request or hostmot2's registration timed out; CI's sanitizer-built card did once
# after a full commissioning run). Such a run ran nothing and measured the host; a last try
# that did not start fails.
realtime_started() {
  local label=$1 try=$2 why
  why=$(grep -m1 -e "rtapi_app_main: " -e "board fails HM2 registration" "$work/hal.out") || return 0
  grep -q "insmod for hm2_eth failed" "$work/hal.out" || return 0
  ((try < STALL_TRIES)) || fail "$label: LinuxCNC's realtime did not start in all $STALL_TRIES runs ($why)"
  note "$label: LinuxCNC's realtime did not start ($why): the run measured this host, not the axis; running it again ($try of $STALL_TRIES)"
  return 1
}

# --- the file `i20 hal` writes, run as LinuxCNC would run it --------------------------------
# generated_hal_files: `i20 hal` writes the card's axes (port 0, channel k = encoder k) to
# $work/generated.hal, with an INI ($work/axis.ini) holding the values the file reads (gains
# 0: the pid's output is its bias, a torque command in amps), and $work/loadable.hal, the file
# less its iocontrol lines: iocontrol needs a running LinuxCNC's NML buffers, so its lines (E-stop
# out, tool change loop) are left out of the load and counted in io_lines. Sets estop_pin, the
# E-stop input the file was given. HAL_CFG: bldc's cfg (default qh); HAL_ARGS (an array, if
# set): more `i20 hal` options.
generated_hal_files() {
  local -a axes_args
  if [[ $CARD == 7i96s ]]; then
    axes_args=(--board 7i96s --axes 1 --halls "$(IFS=,; echo "${HALL_NETS[*]}")"
      --estop-in "$BOARD.inm.00.input-10")
  else
    axes_args=(--board 7i92t --axes 2 --halls "$BOARD.gpio.010.in,$BOARD.gpio.011.in,$BOARD.gpio.012.in"
      --halls "$(IFS=,; echo "${HALL_NETS[*]}")" --estop-in "$BOARD.gpio.016.in")
  fi
  rm -f "$work/generated.hal" # a run again writes it anew
  "$I20" hal "${axes_args[@]}" --board-ip "$CARD_IP" --cfg "${HAL_CFG:-qh}" --pattern 25 --poles $POLES \
    --counts-per-rev $COUNTS --max-current 10A ${HAL_ARGS[@]+"${HAL_ARGS[@]}"} -o "$work/generated.hal" 2>"$work/i20.err" ||
    fail "i20 hal failed: $(cat "$work/i20.err")"
  {
    printf '[KINS]\nKINEMATICS = trivkins coordinates=%s\nJOINTS = %s\n' "$( ((CHANNELS == 1)) && echo X || echo XY)" "$CHANNELS"
    printf '[EMCMOT]\nEMCMOT = motmod\nSERVO_PERIOD = 1000000\n'
    for ((j = 0; j < CHANNELS; j++)); do
      printf '[JOINT_%s]\nENCODER_SCALE = %s\nP = 0\nI = 0\nD = 0\nFF0 = 0\nFF1 = 0\nFF2 = 0\n' "$j" "$COUNTS"
      printf 'BIAS = 0\nDEADBAND = 0\nFERROR = 1\nMIN_FERROR = 0.5\n'
    done
  } >"$work/axis.ini"
  grep -v 'iocontrol\.0\.' "$work/generated.hal" >"$work/loadable.hal"
  io_lines=$(grep -c 'iocontrol\.0\.' "$work/generated.hal")
  estop_pin=$(sed -n 's/^net estop-ext \([^ ]*\) => .*/\1/p' "$work/generated.hal")
  [[ -n $estop_pin ]] || fail "i20 hal did not net --estop-in to estop-ext"
  chmod 644 "$work/loadable.hal" "$work/axis.ini"
}

# generated_preamble [tolerant]: the first lines of a halrun script that runs the generated
# file, machine on from its start. Printed to stdout.
generated_preamble() {
  # The linuxcnc start script loads these before the HAL files (2.9: motmod needs them).
  printf 'loadrt homemod\nloadrt tpmod\nsource %s\n' "$work/loadable.hal"
  # No task runs here to take the machine out of E-stop and turn it on: the test stands in
  # for it (motion-enabled, the joint's amp-enable-out) and for a closed E-stop loop (the
  # input pin).
  printf 'unlinkp motion.motion-enabled\nunlinkp joint.%s.amp-enable-out\nunlinkp %s\n' "$CHANNEL" "$estop_pin"
  # tolerant: this host's servo thread is not realtime, so its late DOITs would stop the port
  # (fault-lim) and its late replies time out; a real machine's thread keeps time, and the
  # generated file leaves fault-lim and packet-read-timeout be. A run whose subject is the
  # port's own stop keeps hostmot2's fault-lim.
  # (The file's own check of that limit, i20-port-stopped, follows it.)
  [[ ${1:-} == tolerant ]] &&
    printf 'setp %s.sserial.port-0.fault-lim 1000000\nsetp i20-port-stopped.in0 1000000\n' "$BOARD"
  printf 'setp %s.packet-read-timeout 20000000\n' "$BOARD"
  printf 'sets estop-ext TRUE\nsets i20-machine-on TRUE\nsets j%s-amp-enable TRUE\n' "$CHANNEL"
  # The servo thread's longest period, for the stall check (kept_time).
  printf 'loadrt timedelta count=1\naddf timedelta.0 servo-thread\n'
}

# run_generated_hal SCRIPT: halrun runs SCRIPT with the generated file's INI, as the HAL user;
# its output in $work/hal.out.
run_generated_hal() {
  hal env INI_FILE_NAME="$work/axis.ini" timeout 90 halrun -i "$work/axis.ini" -f "$1" >"$work/hal.out" 2>&1
}
