#!/bin/bash
# SPDX-License-Identifier: GPL-2.0-or-later
# LinuxCNC's own hm2_eth + bldc close the loop of a virtual axis: the virtual 7I92T
# (i20sim --eth --card 7i92t-servo or 7i96s --motor FILE) serves in a network namespace of its own
# behind a veth pair, and halrun, as an unprivileged user in a second namespace, runs a
# 1 ms servo thread with the motor's true configuration: encoder rawcounts and the three
# Halls into bldc (cfg=qh), bldc's rotor-angle into the 8I20's angle, a torque command
# (amps) through bldc value/out into its current. Checked:
#   - +torque turns the motor forward, -torque turns it back (hostmot2's encoder and the
#     simulator's own motor state agree on it);
#   - bldc.hall-error stays FALSE, the 8I20's fault.watchdog never sets;
#   - hostmot2's encoder position equals the simulator's rotor angle;
#   - with the wrong encoder sign in bldc (scale negated), and with a wrong Hall pattern, the
#     motor does NOT follow: the check above can fail;
#   - the HAL `i20 hal` writes for the card's axes loads against it (every name real), and,
#     enabled (the test standing in for LinuxCNC's task and E-stop loop), its pid turns the
#     motor both ways and the machine drops out of E-stop when the 8I20 latches a fault; its
#     power-up trips nothing, machine off lets E-stop be reset (the port stops, its stale fault
#     no longer counts) and machine on, the cause gone, clears the 8I20's latched fault.
# The namespaces, the simulator and halrun come from rig.sh.
#
# usage: axis_test.sh I20SIM MOTOR_FILE [I20]     exit 0 pass, 1 fail, 77 skipped
set -u

I20SIM=${1:?usage: axis_test.sh I20SIM MOTOR_FILE [I20]}
MOTOR=${2:?usage: axis_test.sh I20SIM MOTOR_FILE [I20]}
I20=${3:-}
# shellcheck source=rig.sh
source "$(dirname "${BASH_SOURCE[0]}")/rig.sh"
TORQUE_A=0.08 # 36 mNm with Kt 0.45 Nm/A against 20 mNm of Coulomb friction

# A signal's reading in halrun's output as "NAME=value" (rig.sh's report reads a pin).
report_signal() { printf 'loadusr -w %s %s\ngets %s\n' "$work/label" "$1" "$2"; }

# The experiment as one HAL file: the axis with the motor's true configuration (`extra`
# appended: a deliberate mistake), then the torque steps and the readings as halcmd lines,
# so their timing does not hang on this script starting processes. Readings come out as
# "NAME=value" lines in halrun's output.
write_axis_hal() {
  local extra=$1 rawcounts=$BOARD.encoder.$ENC.rawcounts
  printf '#!/bin/sh\nread line < %s\n' "$work/release" >"$work/hold"
  chmod 755 "$work/hold"
  rm -f "$work/release"
  mkfifo -m 666 "$work/release"
  torque_for() { printf 'sets torque-cmd %s\nloadusr -w sleep %s\n' "$1" "$2"; }
  {
    printf '%s\n' \
      "loadrt hostmot2" \
      "loadrt hm2_eth board_ip=$CARD_IP" \
      "loadrt bldc cfg=qh" \
      "loadrt timedelta count=1" \
      "loadrt threads name1=servo-thread period1=1000000" \
      "# A 1 ms thread on a loaded, non-realtime host: give each reply 20 ms." \
      "setp $BOARD.packet-read-timeout 20000000" \
      "# It also runs a late period's successor at once, before the card's SSLBP has finished" \
      "# the last DOIT: hostmot2 counts an overrun (fault-inc 10 each, fault-dec 1 per good" \
      "# cycle) and stops the port at fault-lim, which starves the 8I20's watchdog. Tolerate" \
      "# them here; the test reports the count (sserial(9): fault-inc, fault-dec, fault-lim)." \
      "setp $BOARD.sserial.port-0.fault-lim 1000000" \
      "setp $BOARD.encoder.$ENC.scale $COUNTS" \
      "setp bldc.0.scale $COUNTS" \
      "setp bldc.0.poles $POLES" \
      "setp bldc.0.pattern 25" \
      "net hall1 ${HALL_NETS[0]} => bldc.0.hall1" \
      "net hall2 ${HALL_NETS[1]} => bldc.0.hall2" \
      "net hall3 ${HALL_NETS[2]} => bldc.0.hall3" \
      "net rawcounts $rawcounts => bldc.0.rawcounts" \
      "net rotor-angle bldc.0.rotor-angle => $AMP.angle" \
      "net torque-cmd => bldc.0.value" \
      "net phase-current bldc.0.out => $AMP.current" \
      "$extra" \
      "addf $BOARD.read servo-thread" \
      "addf bldc.0 servo-thread" \
      "addf timedelta.0 servo-thread" \
      "addf $BOARD.write servo-thread" \
      "start"
    torque_for 0 0.5
    report start "$rawcounts"
    report max_at_start timedelta.0.max
    report watchdog_at_start "$AMP.fault.watchdog"
    report faults_at_start "$BOARD.sserial.port-0.fault-count"
    torque_for "$TORQUE_A" 0.6
    report forward "$rawcounts"
    torque_for "-$TORQUE_A" 1.2
    report back "$rawcounts"
    torque_for 0 1.5 # friction stops the rotor
    report end "$rawcounts"
    report position "$BOARD.encoder.$ENC.position"
    report hall_error bldc.0.hall-error
    report watchdog "$AMP.fault.watchdog"
    report port_faults "$BOARD.sserial.port-0.fault-count"
    report period_min timedelta.0.min
    report period_max timedelta.0.max
    report period_avg_err timedelta.0.avg-err
    # Stay up, the thread running, until the test has read the simulator.
    printf 'loadusr -w %s done\nloadusr -w %s\n' "$work/label" "$work/hold"
  } >"$work/axis.hal"
  chmod 644 "$work/axis.hal"
}

# printed NAME TENTHS: true once halrun's output has the reading "NAME=", waiting up to TENTHS
# tenths of a second while halrun runs.
printed() {
  local name=$1 tenths=$2
  for _ in $(seq "$tenths"); do
    grep -q "^$name=" "$work/hal.out" && return 0
    kill -0 "$hal_pid" 2>/dev/null || break
    sleep 0.1
  done
  grep -q "^$name=" "$work/hal.out"
}

# One run: forward, back, stop. Sets moved_forward, moved_back (counts), encoder_turns,
# sim_turns and the figures. Returns 1 (run it again) when LinuxCNC's realtime did not start
# on try TRY (rig.sh's realtime_started).
run_axis_once() {
  local label=$1 extra=$2 try=$3
  start_sim
  write_axis_hal "$extra"
  local t0
  t0=$(date +%s.%N)
  hal halrun -f "$work/axis.hal" >"$work/hal.out" 2>&1 &
  hal_pid=$!
  if ! printed done 300; then
    if ! realtime_started "$label" "$try"; then
      timeout 20 tail --pid="$hal_pid" -f /dev/null || fail "halrun did not exit"
      hal_pid=""
      stop_sim
      return 1
    fi
    cat "$work/hal.out"
    fail "$label: halrun did not run the experiment"
  fi
  run_seconds=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
  sim_angle sim_turns # the rotor is at rest now
  echo >"$work/release"
  timeout 20 tail --pid="$hal_pid" -f /dev/null || fail "halrun did not exit"
  hal_pid=""
  stop_sim
  moved_forward=$(($(value forward) - $(value start)))
  moved_back=$(($(value forward) - $(value back)))
  encoder_turns=$(awk -v c="$(value end)" -v n=$COUNTS 'BEGIN { printf "%.5f", c / n }')
  hall_error=$(value hall_error)
  watchdog_bit=$(value watchdog)
  read_errors=$(grep -c -i "error finishing read" "$work/hal.out")
  note "$label: forward $moved_forward counts, back $moved_back counts; encoder $encoder_turns turns" \
    "(position $(value position)), simulator $sim_turns turns; hall-error $hall_error," \
    "fault.watchdog $watchdog_bit, SSERIAL fault-count $(value port_faults); servo period" \
    "min/max $(value period_min)/$(value period_max) ns (avg error $(value period_avg_err) ns);" \
    "$read_errors read errors; halrun $run_seconds s"
}

# run_axis LABEL SETP JUDGE: runs the experiment and judges it with JUDGE, a function that
# prints what failed (nothing when all passed); a failure in a run the host stalled is run
# again (rig.sh's judged).
run_axis() {
  local label=$1 extra=$2 judge=$3 try
  for ((try = 1; ; try++)); do
    run_axis_once "$label" "$extra" "$try" || continue
    judged "$label" "$try" "$($judge)" && return
  done
}
follows() { ((moved_forward > COUNTS / 2 && moved_back > COUNTS / 2)); }

# --- 1. the true configuration: the loop closes ---------------------------------------------
closes_the_loop() {
  if ! follows; then
    cat "$work/hal.out" >&2
    echo "the motor did not follow the torque command (forward $moved_forward, back $moved_back counts)"
  elif [[ $hall_error != FALSE ]]; then
    echo "bldc.0.hall-error went TRUE with the motor's own Hall pattern"
  elif [[ $watchdog_bit != FALSE ]]; then
    echo "the 8I20's watchdog bit while the servo thread ran"
  elif ! awk -v e="$encoder_turns" -v s="$sim_turns" 'BEGIN { d = e - s; exit !(d < 0.001 && d > -0.001) }'; then
    echo "hostmot2's encoder reads $encoder_turns turns, the simulator's rotor is at $sim_turns"
  fi
}
run_axis "true configuration" "" closes_the_loop

# --- 2. wrong configurations: the same check must see the motor not follow -----------------
# (A stall cannot make a wrong configuration follow: these are judged on any run.)
wrong_sign_does_not_follow() {
  if follows; then echo "with bldc's encoder sign wrong the motor still followed: the check cannot fail"; fi
}
run_axis "encoder sign wrong" "setp bldc.0.scale -$COUNTS" wrong_sign_does_not_follow
# ... and a wrong Hall pattern (17 for the motor's 25) must not follow either.
wrong_pattern_does_not_follow() {
  if follows; then echo "with bldc's Hall pattern wrong the motor still followed: the check cannot fail"; fi
}
run_axis "Hall pattern wrong" "setp bldc.0.pattern 17" wrong_pattern_does_not_follow

# --- 3. the HAL `i20 hal` writes for this card loads against it ------------------------------
# Both axes of the card's port 0 (channel k = encoder k), with the motion module and an INI
# holding the values the file reads. halcmd stops at the first line naming a pin,
# signal or component that does not exist, so a clean load means every name is real.
check_generated_hal_once() {
  local try=$1
  generated_hal_files
  local rawcounts=$BOARD.encoder.$ENC.rawcounts pid=pid.$CHANNEL sig=j$CHANNEL-
  {
    generated_preamble tolerant
    # The power-up: the port runs 1 s after machine-on, its faults count 0.5 s later.
    printf 'start\nloadusr -w sleep 2.5\n'
    report ok_before i20-estop-ok.and # the estop-ok signal: its iocontrol end is left out
    report_signal fault_before "${sig}8i20-fault"
    report watchdog "$AMP.fault.watchdog"
    report start "$rawcounts"
    # With the INI's gains at 0 the pid's output is its bias: a torque command in amps.
    printf 'setp %s.bias %s\nloadusr -w sleep 0.6\n' "$pid" "$TORQUE_A"
    report forward "$rawcounts"
    printf 'setp %s.bias -%s\nloadusr -w sleep 1.2\n' "$pid" "$TORQUE_A"
    report back "$rawcounts"
    printf 'setp %s.bias 0\n' "$pid"
    # The test makes the simulator latch an overcurrent now, then lets HAL read on.
    printf 'loadusr -w %s fault_now\nloadusr -w echo\nloadusr -w %s\nloadusr -w sleep 0.5\n' "$work/label" "$work/hold"
    report_signal fault_after "${sig}8i20-fault"
    report ok_after i20-estop-ok.and
    # E-stop turns the machine off: the port stops, and its stale fault no longer holds E-stop.
    printf 'sets i20-machine-on FALSE\nsets %samp-enable FALSE\nloadusr -w sleep 0.3\n' "$sig"
    report ok_off i20-estop-ok.and
    report run_off "$BOARD.sserial.port-0.run"
    report_signal fault_off "${sig}8i20-fault"
    # The test clears the fault's cause in the simulator; machine-on starts the port again.
    printf 'loadusr -w %s cause_cleared\nloadusr -w echo\nloadusr -w %s\n' "$work/label" "$work/hold"
    printf 'sets i20-machine-on TRUE\nsets %samp-enable TRUE\nloadusr -w sleep 2.5\n' "$sig"
    report_signal fault_reset "${sig}8i20-fault"
    report ok_on i20-estop-ok.and
    report period_max timedelta.0.max
    printf 'loadusr -w %s done\n' "$work/label"
  } >"$work/load.hal"
  chmod 644 "$work/load.hal"
  rm -f "$work/release"
  mkfifo -m 666 "$work/release"
  start_sim
  run_generated_hal "$work/load.hal" &
  hal_pid=$!
  printed fault_now 300 || {
    grep -v "IO Pin" "$work/hal.out" | tail -20
    fail "the HAL i20 hal writes did not load against the virtual card"
  }
  [[ $(sim_ask "ch $CHANNEL fault overcurrent on") == ok ]] || fail "the simulator did not take the fault"
  echo >"$work/release"
  printed cause_cleared 100 || {
    grep -v "IO Pin" "$work/hal.out" | tail -20
    fail "halrun did not reach the machine-on after the fault"
  }
  [[ $(sim_ask "ch $CHANNEL fault overcurrent off") == ok ]] || fail "the simulator did not clear the fault"
  echo >"$work/release"
  timeout 30 tail --pid="$hal_pid" -f /dev/null || fail "halrun did not exit"
  hal_pid=""
  stop_sim
  grep -q '^done=' "$work/hal.out" || {
    grep -v "IO Pin" "$work/hal.out" | tail -20
    fail "halrun stopped before the end of the generated configuration's run"
  }
  moved_forward=$(($(value forward) - $(value start)))
  moved_back=$(($(value forward) - $(value back)))
  note "i20 hal: the generated HAL ($CHANNELS axis/axes, motion) loaded and ran, less its $io_lines iocontrol lines;" \
    "enabled: i20-estop-ok.and $(value ok_before), fault.watchdog $(value watchdog); bias +/-$TORQUE_A A moved" \
    "$moved_forward / $moved_back counts; after an overcurrent: ${sig}8i20-fault $(value fault_after)," \
    "i20-estop-ok.and $(value ok_after); machine off: i20-estop-ok.and $(value ok_off), run $(value run_off), ${sig}8i20-fault $(value fault_off);" \
    "cause cleared, machine on: ${sig}8i20-fault $(value fault_reset), i20-estop-ok.and $(value ok_on);" \
    "servo period max $(value period_max) ns"
  local why=""
  if [[ $(value ok_before) != TRUE || $(value fault_before) != FALSE ]]; then
    why="the generated configuration's normal power-up tripped (estop-ok $(value ok_before), 8I20 fault $(value fault_before))"
  elif ! follows; then
    why="the generated configuration's torque command did not turn the motor (forward $moved_forward, back $moved_back counts)"
  elif [[ $(value fault_after) != TRUE ]]; then
    why="the 8I20's overcurrent did not reach ${sig}8i20-fault"
  elif [[ $(value ok_after) != FALSE ]]; then
    why="the machine did not drop out (estop-ok stayed TRUE) on the 8I20's fault"
  elif [[ $(value ok_off) != TRUE || $(value run_off) != FALSE ]]; then
    why="with the machine off the port kept running ($(value run_off)) or its stale fault held E-stop ($(value ok_off))"
  elif [[ $(value fault_reset) != FALSE || $(value ok_on) != TRUE ]]; then
    why="machine-on did not clear the 8I20's latched fault (fault $(value fault_reset), estop-ok $(value ok_on))"
  fi
  judged "i20 hal" "$try" "$why"
}
check_generated_hal() {
  local try
  for ((try = 1; ; try++)); do
    check_generated_hal_once "$try" && return
  done
}
if [[ -n $I20 && -x $I20 ]]; then
  check_generated_hal
else
  note "i20 hal: skipped (no i20 given)"
fi

total=$(awk -v a="$started" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
note "passed in $total s"
exit 0
