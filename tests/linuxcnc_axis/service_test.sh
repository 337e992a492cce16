#!/bin/bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The axis in service (issue 42 item 4): LinuxCNC's halrun runs the file `i20 hal` writes
# against the virtual card (the rig of axis_test.sh), and the test injects what a machine meets
# in the field into the virtual card while it runs. For each scenario:
#   - the machine drops out of E-stop (i20-estop-ok.and FALSE) for every real fault, and for
#     none of the normal power-ups;
#   - `i20 doctor`, given LinuxCNC's own output of that run (halrun's messages and the
#     `show pin` a user pastes), names the injected cause.
# Scenarios: a normal power-up; a bus that rises within the port's start delay (normal); a bus
# still low when the port starts; every one of the 8I20's 13 fault bits held in turn (one
# halrun: each fault trips, machine off resets E-stop, machine on with the cause gone runs
# again); the enable input off; the servo thread stalled past the 8I20's watchdog; half the
# 8I20's replies lost, which stops the port.
#
# usage: service_test.sh I20SIM MOTOR_FILE I20     exit 0 pass, 1 fail, 77 skipped
set -u

I20SIM=${1:?usage: service_test.sh I20SIM MOTOR_FILE I20}
MOTOR=${2:?usage: service_test.sh I20SIM MOTOR_FILE I20}
I20=${3:?usage: service_test.sh I20SIM MOTOR_FILE I20}
RIG_NAME=linuxcnc_service
# shellcheck source=rig.sh
source "$(dirname "${BASH_SOURCE[0]}")/rig.sh"

# Scripts halrun runs (as the HAL user) between its own lines:
#   label NAME          prints "NAME=" (the next getp prints the value)
#   inject LINE...      one control line to the virtual card (its answer goes to the card's log)
#   until PIN VALUE N   waits, polling halcmd every 0.1 s up to N times, until PIN reads VALUE
#   stall SECONDS       stops LinuxCNC's realtime process (its servo thread) that long
cat >"$work/label" <<'SH'
#!/bin/sh
printf "%s=" "$1"
SH
cat >"$work/inject" <<SH
#!/bin/sh
echo "\$*" > $work/ctl
SH
cat >"$work/until" <<'SH'
#!/bin/sh
i=0
while [ "$i" -lt "$3" ] && [ "$(halcmd getp "$1")" != "$2" ]; do
  sleep 0.1
  i=$((i + 1))
done
SH
cat >"$work/stall" <<'SH'
#!/bin/sh
pkill -STOP -x rtapi_app
sleep "$1"
pkill -CONT -x rtapi_app
SH
chmod 755 "$work/label" "$work/inject" "$work/until" "$work/stall"
report() { printf 'loadusr -w %s %s\ngetp %s\n' "$work/label" "$1" "$2"; }
# A scenario's part of LinuxCNC's output starts at its marker line (part, below).
marker() { printf 'loadusr -w echo ==== scenario %s\n' "$1"; }
# The pins a user pastes for the doctor.
show_pins() {
  printf 'show pin %s.sserial\nshow pin %s.8i20.0.%s.fault\nshow pin %s.packet-error\n' "$BOARD" "$BOARD" "$CHANNEL" "$BOARD"
}
# After machine-on: the port runs 1 s later, its faults count 0.5 s after that.
watched() { printf 'loadusr -w %s i20-watching.out TRUE 60\n' "$work/until"; }

generated_hal_files
ESTOP=i20-estop-ok.and
FAULT_PIN=$BOARD.8i20.0.$CHANNEL.fault

# run_scenarios NAME [TOLERANT] < BODY: one halrun of the generated file, machine on from its
# start, BODY's HAL lines after `start`. LinuxCNC's output in $work/NAME.out.
run_scenarios() {
  local name=$1 tolerance=${2:-tolerant} try
  local body
  body=$(cat)
  for ((try = 1; ; try++)); do
    {
      generated_preamble "$tolerance"
      printf 'start\n%s\n' "$body"
      report period_max timedelta.0.max
      printf 'loadusr -w %s done\nloadusr -w echo\n' "$work/label"
    } >"$work/$name.hal"
    chmod 644 "$work/$name.hal"
    start_sim
    chmod 666 "$work/ctl"
    [[ -n ${PRE:-} ]] && sim_ask "$PRE" >/dev/null
    run_generated_hal "$work/$name.hal"
    stop_sim
    cp "$work/hal.out" "$work/$name.out"
    realtime_started "$name" "$try" || continue
    grep -q '^done=' "$work/$name.out" || {
      grep -v "IO Pin" "$work/$name.out" | tail -20
      fail "$name: halrun stopped before the end of its run"
    }
    return 0
  done
}

# part NAME SCENARIO: the lines of run NAME's output from SCENARIO's marker to the next
# marker: LinuxCNC's messages meanwhile and the pins, as the user would paste them.
part() {
  awk -v m="==== scenario $2" '$0 == m { on = 1; next } /^==== scenario / { on = 0 } on' "$work/$1.out" \
    >"$work/$2.txt"
}

# doctor_names SCENARIO ID [TEXT]: i20 doctor, given the scenario's part of LinuxCNC's output,
# names finding ID (with TEXT in its evidence).
doctor_names() {
  local scenario=$1 id=$2 text=${3:-}
  "$I20" doctor --json "$work/$scenario.txt" >"$work/$scenario.json"
  python3 - "$work/$scenario.json" "$id" "$text" <<'PY' && return 0
import json, sys
d = json.load(open(sys.argv[1]))
ok = any(f["id"] == sys.argv[2] and sys.argv[3] in f["evidence"] for f in d["findings"])
sys.exit(0 if ok else 1)
PY
  cat "$work/$scenario.txt"
  "$I20" doctor "$work/$scenario.txt"
  fail "$scenario: i20 doctor did not name $id${text:+ ($text)}"
}

# A reading of run NAME: "LABEL=value".
reading() { awk -v key="$2=" 'index($0, key) == 1 { v = substr($0, length(key) + 1) } END { print v }' "$work/$1.out"; }
tripped=0 stayed_up=0

# --- normal power-ups: nothing trips -------------------------------------------------------
# 1. The bus is up before the machine is switched on.
# 2. The bus rises with the machine, reaching its level 0.6 s later: the port starts at 1 s.
PRE="ch $CHANNEL busv 20" run_scenarios power-up-ramp <<HAL
$(marker power-up-ramp)
loadusr -w sleep 0.2
loadusr -w $work/inject ch $CHANNEL busv 120
loadusr -w sleep 0.2
loadusr -w $work/inject ch $CHANNEL busv 240
loadusr -w sleep 0.2
loadusr -w $work/inject ch $CHANNEL busv 320
$(watched)
loadusr -w sleep 0.3
$(report ok_ramp $ESTOP)
$(report fault_ramp "$FAULT_PIN.bus-underv")
$(show_pins)
HAL
run_scenarios power-up <<HAL
$(marker power-up)
$(watched)
loadusr -w sleep 0.3
$(report ok_normal $ESTOP)
$(show_pins)
HAL
for run in power-up:ok_normal power-up-ramp:ok_ramp; do
  [[ $(reading "${run%%:*}" "${run#*:}") == TRUE ]] || {
    cat "$work/${run%%:*}.out"
    fail "${run%%:*}: a normal power-up dropped the machine out of E-stop"
  }
  stayed_up=$((stayed_up + 1))
done
for scenario in power-up power-up-ramp; do
  part "$scenario" "$scenario"
  "$I20" doctor --json "$work/$scenario.txt" >"$work/$scenario.json"
  python3 - "$work/$scenario.json" <<'PY' || { cat "$work/$scenario.txt"; fail "$scenario: i20 doctor named an 8I20 fault on a normal power-up"; }
import json, sys
d = json.load(open(sys.argv[1]))
sys.exit(1 if any(f["id"] == "pin-8i20-fault" for f in d["findings"]) else 0)
PY
done
note "normal power-ups (bus up; bus rising over 0.6 s): E-stop held by neither, no 8I20 fault named"

# --- the bus still low when the port starts (a supply slower than the start delay) ---------
PRE="ch $CHANNEL busv 20" run_scenarios bus-late <<HAL
$(marker bus-late)
$(watched)
loadusr -w $work/until $ESTOP FALSE 20
$(report ok_bus_late $ESTOP)
$(show_pins)
loadusr -w $work/inject ch $CHANNEL busv 320
HAL
[[ $(reading bus-late ok_bus_late) == FALSE ]] || fail "bus-late: the bus under-voltage did not drop the machine"
part bus-late bus-late
doctor_names bus-late pin-8i20-fault "fault.bus-underv is TRUE"
tripped=$((tripped + 1))
note "bus still low at the port's start: E-stop, named"

# --- every fault bit of the 8I20, in turn, in one run ---------------------------------------
# The simulator's name for each cause, and hostmot2's pin for its bit (docs/linuxcnc-hal.md).
FAULTS=(watchdog:watchdog noenable:no-enable overtemp:overtemp overcurrent:overcurrent
  uloop:U-current vloop:V-current wloop:W-current buslow:bus-underv bushigh:bus-high
  busmax:bus-overv module:module overrun:overrun framing:framingr)
{
  watched
  for f in "${FAULTS[@]}"; do
    cause=${f%%:*}
    marker "$cause"
    printf 'loadusr -w %s ch %s fault %s on\n' "$work/inject" "$CHANNEL" "$cause"
    printf 'loadusr -w %s %s FALSE 20\n' "$work/until" "$ESTOP"
    report "ok_$cause" "$ESTOP"
    show_pins
    # The cause gone, machine off lets E-stop be reset; machine on starts the port again.
    printf 'loadusr -w %s ch %s fault %s off\n' "$work/inject" "$CHANNEL" "$cause"
    printf 'sets i20-machine-on FALSE\nsets j%s-amp-enable FALSE\n' "$CHANNEL"
    printf 'loadusr -w %s %s TRUE 20\n' "$work/until" "$ESTOP"
    report "off_$cause" "$ESTOP"
    printf 'sets i20-machine-on TRUE\nsets j%s-amp-enable TRUE\n' "$CHANNEL"
    watched
    printf 'loadusr -w sleep 0.2\n'
    report "again_$cause" "$ESTOP"
  done
} >"$work/fault-bits.body"
run_scenarios fault-bits <"$work/fault-bits.body"
for f in "${FAULTS[@]}"; do
  cause=${f%%:*} pin=${f#*:}
  [[ $(reading fault-bits "ok_$cause") == FALSE ]] || fail "fault $cause: the machine stayed out of E-stop ($ESTOP $(reading fault-bits "ok_$cause"))"
  [[ $(reading fault-bits "off_$cause") == TRUE ]] || fail "fault $cause: machine off did not let E-stop be reset"
  [[ $(reading fault-bits "again_$cause") == TRUE ]] || fail "fault $cause: machine on, the cause gone, did not run again"
  part fault-bits "$cause"
  doctor_names "$cause" pin-8i20-fault "fault.$pin is TRUE"
  tripped=$((tripped + 1))
done
note "each of the ${#FAULTS[@]} fault bits: E-stop, reset by machine off and on, named"

# --- the enable input off (the E-stop chain's contactor, a cut cable) -----------------------
run_scenarios enable-off <<HAL
$(watched)
$(marker enable-off)
loadusr -w $work/inject ch $CHANNEL enable off
loadusr -w $work/until $ESTOP FALSE 20
$(report ok_enable_off $ESTOP)
$(show_pins)
HAL
[[ $(reading enable-off ok_enable_off) == FALSE ]] || fail "enable-off: the machine stayed out of E-stop"
part enable-off enable-off
doctor_names enable-off pin-8i20-fault "fault.no-enable is TRUE"
tripped=$((tripped + 1))
note "enable input off: E-stop, named"

# --- the servo thread stalled past the 8I20's 40 ms watchdog --------------------------------
run_scenarios thread-stalled <<HAL
$(watched)
$(marker thread-stalled)
loadusr -w $work/stall 0.15
loadusr -w $work/until $ESTOP FALSE 20
$(report ok_stalled $ESTOP)
$(show_pins)
HAL
[[ $(reading thread-stalled ok_stalled) == FALSE ]] || fail "thread-stalled: the machine stayed out of E-stop"
part thread-stalled thread-stalled
doctor_names thread-stalled pin-8i20-fault "fault.watchdog is TRUE"
tripped=$((tripped + 1))
note "servo thread stalled 150 ms: E-stop, named"

# --- half the 8I20's replies lost: hostmot2 stops the port (its own fault-lim) --------------
run_scenarios lossy-8i20 strict <<HAL
$(watched)
$(marker lossy-8i20)
loadusr -w $work/inject ch $CHANNEL drop 0.5
loadusr -w $work/until $ESTOP FALSE 50
$(report ok_lossy $ESTOP)
$(report count_lossy "$BOARD.sserial.port-0.fault-count")
$(show_pins)
HAL
[[ $(reading lossy-8i20 ok_lossy) == FALSE ]] || fail "lossy-8i20: the port was stopped but the machine stayed out of E-stop (fault-count $(reading lossy-8i20 count_lossy))"
part lossy-8i20 lossy-8i20
doctor_names lossy-8i20 sserial-port-stopped
tripped=$((tripped + 1))
note "half the 8I20's replies lost: the port stopped (fault-count $(reading lossy-8i20 count_lossy)), E-stop, named"

total=$(awk -v a="$started" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
echo "PASS: $tripped injected faults each dropped the machine out of E-stop and i20 doctor named each from LinuxCNC's output; $stayed_up normal power-ups tripped nothing ($total s)"
exit 0
