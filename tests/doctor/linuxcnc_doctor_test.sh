#!/bin/bash
# SPDX-License-Identifier: GPL-2.0-or-later
# `i20 doctor` names the injected cause from LinuxCNC's own output: LinuxCNC's halrun runs
# hm2_eth against the virtual 7I96S (i20sim --eth in a network namespace, the rig of
# tests/linuxcnc_axis), one cause injected per run through the simulator's control lines,
# the run ends with `halcmd show pin` of the card's smart-serial, 8I20 and packet-error
# pins (as a user pastes it), and i20 doctor --json must name the cause.
# I20_DOCTOR_CAPTURE_DIR=DIR keeps each run's output there (tests/doctor/data came so).
#
# usage: linuxcnc_doctor_test.sh I20SIM I20     exit 0 pass, 1 fail, 77 skipped
set -u
I20SIM=${1:?usage: linuxcnc_doctor_test.sh I20SIM I20}
I20=${2:?usage: linuxcnc_doctor_test.sh I20SIM I20}
MOTOR=""
I20_AXIS_CARD=7i96s
RIG_NAME=linuxcnc_doctor
# shellcheck source=../../apps/halrun-virtual/rig.sh
source "$(dirname "${BASH_SOURCE[0]}")/../../apps/halrun-virtual/rig.sh"

printf '#!/bin/sh\necho "$*" > %s\n' "$work/ctl" >"$work/inject"
chmod 755 "$work/inject"

# run NAME PERIOD_NS PRE INJECT [TOLERANT]: the simulator started, PRE sent before LinuxCNC
# starts, INJECT a second after its servo thread started; LinuxCNC's output in $work/NAME.out.
# TOLERANT (1) raises the port's fault-lim, as tests/linuxcnc_axis does: on a loaded,
# non-realtime host late cycles alone can stop the port before the injection, which would
# freeze the pins that show it (those runs test the pins, not the counter).
run() {
  local name=$1 period=$2 pre=$3 inject=$4 tolerant=${5:-0} limit=""
  ((tolerant)) && limit="setp $BOARD.sserial.port-0.fault-lim 1000000"
  start_sim
  chmod 666 "$work/ctl"
  [[ -n $pre ]] && sim_ask "$pre" >/dev/null
  cat >"$work/$name.hal" <<HAL
loadrt hostmot2
loadrt hm2_eth board_ip=$CARD_IP
loadrt threads name1=servo-thread period1=$period
$limit
addf $BOARD.read servo-thread
addf $BOARD.write servo-thread
start
loadusr -w sleep 1
loadusr -w $work/inject ${inject:-show}
loadusr -w sleep 2
show pin $BOARD.sserial
show pin $BOARD.8i20
show pin $BOARD.packet-error
HAL
  chmod 644 "$work/$name.hal"
  hal halrun -f "$work/$name.hal" >"$work/$name.out" 2>&1
  stop_sim
  [[ -n ${I20_DOCTOR_CAPTURE_DIR:-} ]] && cp "$work/$name.out" "$I20_DOCTOR_CAPTURE_DIR/halrun-$name.txt"
  "$I20" doctor --json "$work/$name.out" >"$work/$name.json"
  status=$?
  "$I20" doctor "$work/$name.out" >"$work/$name.txt"
}

# names NAME ID [TEXT]: the doctor's findings for run NAME include ID (with TEXT in its evidence).
names() {
  local name=$1 id=$2 text=${3:-}
  python3 - "$work/$name.json" "$id" "$text" <<'PY' && return 0
import json, sys
d = json.load(open(sys.argv[1]))
ok = any(f["id"] == sys.argv[2] and sys.argv[3] in f["evidence"] for f in d["findings"])
sys.exit(0 if ok else 1)
PY
  cat "$work/$name.out" "$work/$name.txt"
  echo "the virtual card's answers to the control lines (the injection's among them):"
  cat "$work/sim.out" "$work/sim.err"
  fail "$name: i20 doctor did not name $id${text:+ ($text)}"
}
exit_is() {
  ((status == $2)) || { cat "$work/$1.txt"; fail "$1: i20 doctor exit $status, not $2"; }
}

# 1. The bus still rising when LinuxCNC starts the port: 20 V, then 320 V a second later.
#    The 8I20 latched bus under-voltage and keeps it (sticky); LinuxCNC shows it by the pin.
run bus-rising 4000000 "ch 0 busv 20" "ch 0 busv 320" 1
names bus-rising pin-8i20-fault "fault.bus-underv is TRUE"
exit_is bus-rising 1
note "bus rising at power-up: named ($(grep -c . "$work/bus-rising.out") lines of LinuxCNC output)"

# 2. A remote fault while running (over-current held on the 8I20).
run remote-fault 4000000 "" "ch 0 fault overcurrent on" 1
names remote-fault pin-8i20-fault "fault.overcurrent is TRUE"
note "remote fault: named"

# 3. Half the 8I20's replies lost: the card's link errors, the error counter, the port stopped.
#    Whether LinuxCNC prints a "local error" line before the port stops depends on the host's
#    timing (a DOIT the lost replies delayed is found unfinished, "DoIt not cleared", and
#    counted without its error bits). This step failed once in 11 runs here with no "local
#    error" named and its output not kept; the doctor is now held to name one whenever LinuxCNC
#    printed one (a line it cannot name fails as before, with the output), and a run without
#    one says so. tests/doctor/data holds printed ones, named by the unit tests.
run lossy-8i20 4000000 "" "ch 0 drop 0.5"
if grep -q "Smart serial card .* error = " "$work/lossy-8i20.out"; then
  names lossy-8i20 local-link-error
else
  note "8I20 replies lost: LinuxCNC printed no local error line this run: $(grep -c "DoIt not cleared" "$work/lossy-8i20.out") DoIt-not-cleared line(s)"
fi
names lossy-8i20 sserial-comms-error
names lossy-8i20 sserial-port-stopped "smart-serial port 0 of $BOARD was stopped"
note "8I20 replies lost: named, port stopped"

# 4. The card stops answering for 300 ms: hm2_eth's reads fail.
run card-silent 4000000 "" "card reset 300" 1
names card-silent read-error
note "card silent: named"

# 5. A servo thread far too fast for the link (250 us): depending on the host's timing
#    hm2_eth's reads fail (error finishing read) or the smart-serial transfer is still
#    pending at the next cycle (DoIt not cleared); either names the cause.
run thread-too-fast 250000 "" ""
grep -q '"id": *"read-error"' "$work/thread-too-fast.json" || names thread-too-fast doit-not-cleared
note "servo thread too fast: named"

# 6. Nothing injected: none of the causes above is named, and no line is unrecognised. (On a
#    loaded, non-realtime host the run may still lose replies, see DoIt not cleared, or have
#    the 8I20's watchdog bite when the servo thread stalls past 40 ms (a sanitizer build in
#    CI did): that is the host, said truthfully, so those are not judged here.)
run clean 4000000 "" "" 1
python3 - "$work/clean.json" <<'PY' || { cat "$work/clean.txt"; fail "clean run: an injected cause named, or a line not recognised"; }
import json, sys
d = json.load(open(sys.argv[1]))
injected = {"local-link-error", "remote-under-voltage", "remote-over-current"}
injected_pins = ("fault.bus-underv", "fault.overcurrent")
bad = [f["id"] for f in d["findings"]
       if f["id"] in injected or (f["id"] == "pin-8i20-fault" and any(p in f["evidence"] for p in injected_pins))]
print("clean run findings:", [f["id"] for f in d["findings"]], "unrecognised:", len(d["unrecognised"]))
sys.exit(1 if bad or d["unrecognised"] else 0)
PY

# 7. --passive beside the running LinuxCNC: the bus rose after the port started; the card
#    itself shows the bus now up and BUSLOVFAULT still latched. hm2_eth's firewall refuses
#    other programs' packets to the card on the LinuxCNC host (hm2_eth(9)); root's are let
#    through here, as a user runs i20 from another machine or lets it through likewise.
#    Each step waits for its event (CI's sanitizer run once read the card before hm2_eth had
#    started the port, after fixed waits of 2.5 s and 0.5 s): halrun's hold script marks that
#    the thread runs, the 8I20's bus-underv pin that the port runs, and the doctor is asked
#    again (each ask is one observation) until it reads the bus LinuxCNC's cycles refreshed.
start_sim
sim_ask "ch 0 busv 20" >/dev/null
make_hold
mkfifo -m 666 "$work/release"
cat >"$work/passive.hal" <<HAL
loadrt hostmot2
loadrt hm2_eth board_ip=$CARD_IP
loadrt threads name1=servo-thread period1=4000000
setp $BOARD.sserial.port-0.fault-lim 1000000
addf $BOARD.read servo-thread
addf $BOARD.write servo-thread
start
loadusr -w $work/hold running
HAL
chmod 644 "$work/passive.hal"
hal timeout 120 halrun -f "$work/passive.hal" >"$work/passive.out" 2>&1 &
hal_pid=$!
# until TRIES COMMAND...: COMMAND succeeds within TRIES tries 0.1 s apart while halrun runs.
until_true() {
  local tries=$1
  shift
  for _ in $(seq "$tries"); do
    "$@" && return 0
    kill -0 "$hal_pid" 2>/dev/null || return 1
    sleep 0.1
  done
  return 1
}
until_true 600 test -e "$work/marks/at-running" || { cat "$work/passive.out"; fail "--passive: halrun did not start its thread"; }
port_shows_bus_fault() { [[ $(hal halcmd getp "$AMP.fault.bus-underv" 2>/dev/null) == TRUE ]]; }
until_true 600 port_shows_bus_fault || { cat "$work/passive.out"; fail "--passive: LinuxCNC's port never showed the 8I20's latched bus under-voltage"; }
sim_ask "ch 0 busv 320" >/dev/null
ip netns exec "$ns_host" iptables -I OUTPUT 1 -m owner --uid-owner 0 -j ACCEPT
doctor_reads_bus_up() {
  ip netns exec "$ns_host" "$I20" --eth "$CARD_IP" doctor --passive --json >"$work/passive.json"
  status=$?
  python3 -c 'import json, sys; a = json.load(open(sys.argv[1]))["card"]["amplifiers"][0]; sys.exit(0 if a["busv_v"] > 300 else 1)' \
    "$work/passive.json" 2>/dev/null
}
until_true 100 doctor_reads_bus_up
echo >"$work/release"
wait "$hal_pid"
hal_pid=""
stop_sim
python3 - "$work/passive.json" <<'PY' || { cat "$work/passive.json"; fail "--passive: the latched BUSLOVFAULT at 320 V was not reported"; }
import json, sys
c = json.load(open(sys.argv[1]))["card"]
a = c["amplifiers"][0]
print("passive:", c["host"], "bus", a["busv_v"], "V, FAULT", hex(a["fault"]))
sys.exit(0 if c["reached"] and a["live"] and a["fault"] & 0x100 and a["busv_v"] > 300 else 1)
PY
((status == 1)) || fail "--passive with a latched fault: exit $status, not 1"
echo "PASS: i20 doctor named the injected cause in all 5 runs through LinuxCNC; the clean run names none of them; --passive read the latched fault beside the running LinuxCNC"
