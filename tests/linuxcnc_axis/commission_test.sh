#!/bin/bash
# SPDX-License-Identifier: GPL-2.0-or-later
# `i20 commission` hands LinuxCNC a setup that turns the motor the right way: on the virtual
# axis (rig.sh: i20sim in a network namespace of its own, halrun as an unprivileged user in
# another), `i20 commission` finds the commutation and writes its HAL fragment; halrun then
# loads that fragment as written with hm2_eth and bldc against the same virtual card, and
#   - a positive torque command turns the motor forward, a negative one back;
#   - bldc.hall-error stays FALSE;
#   - the first move: whatever the speed at which the rotor first passes the index (seeded
#     random, up to 1,000 rpm, the top speed always), LinuxCNC's commutation with the fragment
#     is within 2 electrical degrees of the motor's truth: the angle of the current the virtual
#     8I20 drives at standstill, from the model's own i_d and i_q, and bldc's stored index
#     position equals hostmot2's (rawcounts - count); with bldc reading rawcounts directly (the
#     arrangement before the index capture) the same measurement shows the late read's error;
#   - the same first moves with the whole file `i20 hal --cfg qhi` writes (pid, E-stop chain,
#     power-up) with the encoder-offset `i20 commission` found: within 2 degrees too.
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
counts=$BOARD.encoder.$ENC.rawcounts
# with_fragment REWIRE: the HAL lines that run the fragment as written (REWIRE after it)
# against the virtual card in a 1 ms servo thread, up to `start`; torque-cmd into bldc.
with_fragment() {
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
    "$1" \
    "addf $BOARD.write servo-thread" \
    "addf timedelta.0 servo-thread" \
    "net torque-cmd => bldc.0.value" \
    "start"
}
{
  with_fragment ""
  printf '%s\n' "loadusr -w sleep 0.5"
  report start "$counts"
  printf 'sets torque-cmd %s\nloadusr -w sleep 0.6\n' "$TORQUE_A"
  report forward "$counts"
  printf 'sets torque-cmd -%s\nloadusr -w sleep 1.2\n' "$TORQUE_A"
  report back "$counts"
  printf 'sets torque-cmd 0\n'
  report hall_error bldc.0.hall-error
  report watchdog "$AMP.fault.watchdog"
  report period_max timedelta.0.max
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

# --- 3. the first move: the index passed at speed, the commutation after it -----------------
# The rotor is spun by the simulator (a driving load against a viscous friction that settles it
# at the speed within about 15 ms) while bldc, still on its Halls, commands no current; once
# hostmot2 has cleared index-enable the brake stops it, and bldc commands 1 A into the held
# rotor. The 8I20 drives that current at bldc's angle: its angle off the torque axis,
# atan2(i_d, i_q), is the commutation error, whatever the speed was.
SEED=${I20_TEST_SEED:-$(date +%s)}
RANDOM=$SEED
TEST_CURRENT_A=1.0
VISCOUS=0.012 # Nm/(rad/s): with the motor's 0.6 kgcm^2, a 5 ms time constant
make_hold
sim_motor() { sim_ask "ch $CHANNEL motor $*" >/dev/null; }
# The HAL file of one first move; `rewire` replaces the capture (the control run), or is
# "generated": the file `i20 hal` wrote (generated_hal_files), whose pid (gains 0) puts out
# its bias, a current in amps, and whose port runs 1 s after machine-on.
write_first_move_hal() {
  local rewire=$1 bldc=bldc.0 current="sets torque-cmd"
  {
    if [[ $rewire == generated ]]; then
      bldc=bldc.$CHANNEL current="setp pid.$CHANNEL.bias"
      generated_preamble tolerant
      printf '%s\n' "start" "loadusr -w sleep 2"
    else
      with_fragment "$rewire"
      printf '%s\n' "loadusr -w sleep 0.3"
    fi
    printf '%s\n' \
      "loadusr -w $work/hold spin" \
      "$current $TEST_CURRENT_A" \
      "loadusr -w sleep 0.4"
    report index_enable "$bldc.index-enable"
    report offset "$bldc.offset-measured"
    report rawcounts "$counts"
    report count "$BOARD.encoder.$ENC.count"
    printf '%s\n' "loadusr -w $work/hold measure"
    # Read once the test has read the 8I20's current (held at "measure"): a period that
    # stalled, or a watchdog that bit, before that reading shows here (CI read 0 A at
    # standstill after reports taken before the reading had shown neither).
    report watchdog "$AMP.fault.watchdog"
    report period_max timedelta.0.max
    printf '%s\n' "$current 0"
  } >"$work/first.hal"
  chmod 644 "$work/first.hal"
}
# The first move's halrun, in the background (hal_pid).
start_first_move_hal() {
  if [[ $1 == generated ]]; then
    hal env INI_FILE_NAME="$work/axis.ini" timeout 60 halrun -i "$work/axis.ini" -f "$work/first.hal" >"$work/hal.out" 2>&1 &
  else
    hal timeout 60 halrun -f "$work/first.hal" >"$work/hal.out" 2>&1 &
  fi
  hal_pid=$!
}
# until_seen FILE: waits (up to 30 s) for halrun's hold script to have created FILE.
until_seen() {
  for _ in $(seq 300); do
    [[ -e $1 ]] && return 0
    kill -0 "$hal_pid" 2>/dev/null || return 1
    sleep 0.1
  done
  return 1
}
# first_move LABEL RPM REWIRE TRY: one run; sets error_deg, stored_error_deg, index_rpm, current_a,
# output (the 8I20's bridge at the measurement) and longest (the run's longest gap, for judged).
first_move() {
  local label=$1 rpm=$2 rewire=$3 try=$4 load index_pin=bldc.0.index-enable
  [[ $rewire == generated ]] && index_pin=bldc.$CHANNEL.index-enable
  # A run again after a stall: the 8I20's watchdog fault may be latched (as above).
  ((try == 1)) || { stop_sim && start_sim; }
  write_first_move_hal "$rewire"
  rm -f "$work/release" "$work"/marks/at-*
  mkfifo -m 666 "$work/release"
  sim_motor brake.engaged false
  start_first_move_hal "$rewire"
  if ! until_seen "$work/marks/at-spin"; then
    wait "$hal_pid"
    hal_pid=""
    realtime_started "$label" "$try" || return 1
    cat "$work/hal.out"
    fail "$label: halrun did not start the first move"
  fi
  load=$(awk -v r="$rpm" -v b=$VISCOUS 'BEGIN { printf "%.4f", -(b * r * 2 * 3.14159265 / 60 + 0.02) }')
  sim_motor friction.viscous "${VISCOUS}Nm/(rad/s)"
  sim_motor load "${load}Nm"
  for _ in $(seq 200); do
    [[ $(hal halcmd getp "$index_pin" 2>/dev/null) == FALSE ]] && break
    sleep 0.02
  done
  sim_reading index_rpm speed
  sim_motor load 0Nm
  sim_motor brake.engaged true
  sim_motor friction.viscous 0.05mNm/\(rad/s\)
  echo >"$work/release"
  until_seen "$work/marks/at-measure" || {
    cat "$work/hal.out"
    fail "$label: halrun did not reach the measurement"
  }
  local id iq
  sim_reading id id
  sim_reading iq iq
  sim_field output output
  echo >"$work/release"
  timeout 20 tail --pid="$hal_pid" -f /dev/null || fail "halrun did not exit"
  hal_pid=""
  error_deg=$(awk -v d="$id" -v q="$iq" 'BEGIN { printf "%.2f", atan2(d, q) * 45 / atan2(1, 1) }')
  current_a=$(awk -v d="$id" -v q="$iq" 'BEGIN { printf "%.3f", sqrt(d * d + q * q) }')
  # bldc's stored index position against hostmot2's, in electrical degrees.
  stored_error_deg=$(awk -v o="$(value offset)" -v r="$(value rawcounts)" -v c="$(value count)" \
    -v p=$((POLES / 2)) -v n="$COUNTS" 'BEGIN { printf "%.2f", (o - (r - c)) * 360 * p / n }')
  # The 8I20's watchdog is the card's own measure of the host's gaps (rig.sh's kept_time): a
  # bite is a gap of at least the watchdog, a run that measured the host.
  longest=$(value period_max)
  [[ $(value watchdog) == FALSE ]] || {
    [[ $longest =~ ^[0-9]+$ ]] && ((longest > WATCHDOG_NS)) || longest=$WATCHDOG_NS
    note "$label: the 8I20's watchdog bit, a gap of at least $((WATCHDOG_NS / 1000000)) ms at the card"
  }
  note "$label: index passed at $index_rpm rpm; current at standstill id $id A, iq $iq A, output $output:" \
    "$error_deg electrical degrees off the torque axis; bldc's stored index $stored_error_deg degrees" \
    "from hostmot2's; index-enable $(value index_enable), fault.watchdog $(value watchdog)," \
    "servo period max $(value period_max) ns"
}
abs() { awk -v x="$1" 'BEGIN { print (x < 0 ? -x : x) }'; }
within() { awk -v x="$1" -v limit="$2" 'BEGIN { exit !((x < 0 ? -x : x) <= limit) }'; }
# driven: the 8I20 drove at least half of bldc's test current (bldc's amplitude is its command).
driven() { awk -v i="$current_a" -v want="$TEST_CURRENT_A" 'BEGIN { exit !(i >= want / 2) }'; }
judge_capture() {
  if [[ $(value index_enable) != FALSE ]]; then
    echo "bldc's index-enable still TRUE: the rotor did not pass the index"
  elif [[ $(value watchdog) != FALSE ]]; then
    echo "the 8I20's watchdog bit: no current was driven"
  elif [[ $output != on ]]; then
    echo "the 8I20's output was $output at the measurement with no watchdog fault"
  elif ! driven; then
    echo "the 8I20 drove $current_a A at standstill for bldc's $TEST_CURRENT_A A: its angle means nothing"
  elif ! within "$error_deg" 2; then
    echo "the current stands $error_deg electrical degrees off the torque axis (more than 2)"
  elif ! within "$stored_error_deg" 0.5; then
    echo "bldc stored the index $stored_error_deg electrical degrees from hostmot2's latched position"
  fi
}
note "first moves: seed $SEED (I20_TEST_SEED repeats them)"
speeds=(1000 $((60 + RANDOM % 940)) $((60 + RANDOM % 940)) $((60 + RANDOM % 940)))
for rpm in "${speeds[@]}"; do
  for ((try = 1; ; try++)); do
    first_move "first move at $rpm rpm" "$rpm" "" "$try" || continue
    judged "first move at $rpm rpm" "$try" "$(judge_capture)" "$longest" && break
  done
done
# The control: bldc reads rawcounts itself (unlinked from the capture) at the top speed.
# The same measurement must see the late read: the current's angle agrees with the error of
# bldc's stored index, whatever it came to this time.
judge_control() {
  if [[ $(value index_enable) != FALSE ]]; then
    echo "bldc's index-enable still TRUE: the rotor did not pass the index"
  elif [[ $(value watchdog) != FALSE ]]; then
    echo "the 8I20's watchdog bit: no current was driven"
  elif [[ $output != on ]]; then
    echo "the 8I20's output was $output at the measurement with no watchdog fault"
  elif ! driven; then
    echo "the 8I20 drove $current_a A at standstill for bldc's $TEST_CURRENT_A A: its angle means nothing"
  elif ! awk -v a="$(abs "$error_deg")" -v b="$(abs "$stored_error_deg")" 'BEGIN { d = a - b; exit !(d < 1 && d > -1) }'; then
    echo "the current's angle ($error_deg degrees) does not show bldc's late index ($stored_error_deg degrees): the measurement cannot tell"
  fi
}
for ((try = 1; ; try++)); do
  first_move "control, bldc report rawcounts itself, at 1000 rpm" 1000 \
    "unlinkp bldc.0.rawcounts
net bldc0-rawcounts bldc.0.rawcounts" "$try" || continue
  judged "control at 1000 rpm" "$try" "$(judge_control)" "$longest" && break
done

# --- 4. the same first moves with the file `i20 hal --cfg qhi` writes ------------------------
# The whole file as LinuxCNC runs it (motion, pid, the E-stop chain, the power-up), with the
# encoder-offset the fragment carries (i20 commission found it), at the top speed and one
# random speed.
offset=$(sed -n 's/^setp bldc\.0\.encoder-offset \(-\{0,1\}[0-9][0-9]*\).*/\1/p' "$work/axis.hal")
[[ -n $offset ]] || fail "the fragment has no encoder-offset: $(cat "$work/axis.hal")"
HAL_CFG=qhi HAL_ARGS=(--encoder-offset "$offset")
generated_hal_files
grep -q "^loadrt bldc cfg=qhi" "$work/generated.hal" || fail "i20 hal --cfg qhi wrote no bldc with the index"
for rpm in 1000 $((60 + RANDOM % 940)); do
  for ((try = 1; ; try++)); do
    first_move "i20 hal --cfg qhi, first move at $rpm rpm" "$rpm" generated "$try" || continue
    judged "i20 hal --cfg qhi, first move at $rpm rpm" "$try" "$(judge_capture)" "$longest" && break
  done
done
note "PASS"
