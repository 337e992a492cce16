#!/bin/bash
# SPDX-License-Identifier: GPL-2.0-or-later
# `i20 commission` hands LinuxCNC a setup that turns the motor the right way: on the virtual
# axis (rig.sh: i20sim in a network namespace of its own, halrun as an unprivileged user in
# another), `i20 commission` finds the commutation and writes its HAL fragment; halrun then
# loads that fragment as written with hm2_eth and bldc against the same virtual card, and
#   - a positive torque command turns the motor forward, a negative one back;
#   - bldc.hall-error stays FALSE.
#
# usage: commission_test.sh I20SIM MOTOR_FILE I20     exit 0 pass, 1 fail, 77 skipped
set -u

I20SIM=${1:?usage: commission_test.sh I20SIM MOTOR_FILE I20}
MOTOR=${2:?usage: commission_test.sh I20SIM MOTOR_FILE I20}
I20=${3:?usage: commission_test.sh I20SIM MOTOR_FILE I20}
# shellcheck source=rig.sh
source "$(dirname "${BASH_SOURCE[0]}")/rig.sh"
TORQUE_A=0.08 # 36 mNm with Kt 0.45 Nm/A against 20 mNm of Coulomb friction

start_sim

# --- 1. commission the axis from the host namespace, as a user on the machine would -------
# A run the loaded host starved past the 8I20's watchdog (WATCHDOG latched, its own worst DOIT
# gap, from its report, past the watchdog) measured the host: it is run again (rig.sh's kept_time).
for ((try = 1; ; try++)); do
  t0=$(date +%s.%N)
  $RT ip netns exec "$ns_host" "$I20" --no-user-params --eth "$CARD_IP" --channel "$CHANNEL" commission --yes \
    --poles "$POLES" --counts-per-rev "$COUNTS" -o "$work/axis.hal" >"$work/commission.out" 2>"$work/commission.err"
  rc=$?
  note "i20 commission: exit $rc in $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s"
  ((rc != 0)) && grep -q WATCHDOG "$work/commission.out" "$work/commission.err" || break
  worst_ns=$(sed -n 's/.* ms, worst \([0-9.]*\) ms$/\1/p' "$work/commission.out" | awk '{ printf "%d", $1 * 1e6 }')
  kept_time "i20 commission" "$try" "${worst_ns:-0}" "$WATCHDOG_NS" && break
done
((rc == 0)) || {
  cat "$work/commission.out" "$work/commission.err"
  fail "i20 commission did not find and check the commutation"
}
grep -q "^setp bldc.0.pattern 25$" "$work/axis.hal" || fail "the fragment has not the motor's pattern 25: $(cat "$work/axis.hal")"
chmod 644 "$work/axis.hal"

# --- 2. LinuxCNC loads the fragment as written and turns the motor with it ----------------
# Readings come out as "NAME=value" lines in halrun's output.
# shellcheck disable=SC2016  # $1 is the label script's own argument
printf '#!/bin/sh\nprintf "%%s=" "$1"\n' >"$work/label"
chmod 755 "$work/label"
reading() { printf 'loadusr -w %s %s\ngetp %s\n' "$work/label" "$1" "$2"; }
counts=$BOARD.encoder.$ENC.rawcounts
{
  printf '%s\n' \
    "loadrt hostmot2" \
    "loadrt hm2_eth board_ip=$CARD_IP" \
    "loadrt threads name1=servo-thread period1=1000000" \
    "loadrt timedelta count=1" \
    "setp $BOARD.packet-read-timeout 20000000" \
    "# overruns of a non-realtime 1 ms thread must not stop the port (as in axis_test.sh)" \
    "setp $BOARD.sserial.port-0.fault-lim 1000000" \
    "addf $BOARD.read servo-thread" \
    "source $work/axis.hal" \
    "addf $BOARD.write servo-thread" \
    "addf timedelta.0 servo-thread" \
    "net torque-cmd => bldc.0.value" \
    "start" \
    "loadusr -w sleep 0.5"
  reading start "$counts"
  printf 'sets torque-cmd %s\nloadusr -w sleep 0.6\n' "$TORQUE_A"
  reading forward "$counts"
  printf 'sets torque-cmd -%s\nloadusr -w sleep 1.2\n' "$TORQUE_A"
  reading back "$counts"
  printf 'sets torque-cmd 0\n'
  reading hall_error bldc.0.hall-error
  reading watchdog "$AMP.fault.watchdog"
  reading period_max timedelta.0.max
} >"$work/run.hal"
chmod 644 "$work/run.hal"
for ((try = 1; ; try++)); do
  # A stalled run may have left the 8I20 with its watchdog fault latched: power the virtual card up
  # again (the same motor file, so the same motor) as one would the machine.
  ((try == 1)) || { stop_sim && start_sim; }
  hal timeout 60 halrun -f "$work/run.hal" >"$work/hal.out" 2>&1
  realtime_started "with the fragment" "$try" || continue
  [[ -n $(value watchdog) ]] || {
    cat "$work/hal.out"
    fail "halrun did not run the experiment with the fragment"
  }
  forward=$(($(value forward) - $(value start)))
  back=$(($(value forward) - $(value back)))
  note "with the fragment: +$TORQUE_A A moved $forward counts, -$TORQUE_A A moved back $back counts;" \
    "hall-error $(value hall_error), fault.watchdog $(value watchdog); servo period max $(value period_max) ns"
  why=""
  if ((forward <= COUNTS / 4)); then
    why="a positive torque did not turn the motor forward ($forward counts)"
  elif ((back <= COUNTS / 4)); then
    why="a negative torque did not turn the motor back ($back counts)"
  elif [[ $(value hall_error) != FALSE ]]; then
    why="bldc.0.hall-error went TRUE with the fragment's pattern"
  elif [[ $(value watchdog) != FALSE ]]; then
    why="the 8I20's watchdog bit while the servo thread kept time"
  fi
  judged "with the fragment" "$try" "$why" && break
done
note "PASS"
