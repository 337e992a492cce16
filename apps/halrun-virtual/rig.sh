# shellcheck shell=bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The rig of `i20 hal lint --load` and of the LinuxCNC tests on the virtual axis, sourced by
# them (not run): the virtual card
# (i20sim --eth --card CARD --motor FILE) in a network namespace of its own behind a veth
# pair, halrun as an unprivileged user in a second namespace, and a cleanup that leaves
# nothing behind (namespaces, rtapi_app, the simulator, the work folder).
# Why namespaces: hm2_eth sets a static ARP entry for the board (LinuxCNC hm2_eth.c), which
# fails on loopback, and it edits iptables; both stay inside the test's own namespaces.
#
# Before sourcing, set I20SIM (the simulator) and MOTOR (its motor file, or "" for a card
# without a motor). I20_AXIS_CARD picks the card, I20_RIG_CARD_IP its address (default
# 192.168.1.121), I20_RIG_CHANNELS how many 8I20s it has, I20_AXIS_TEST_USER the HAL user
# (default nobody). Skips (exit 77, the reason on stdout) without root, `ip netns`,
# halrun, runuser or the HAL user. Gives: skip, fail, note;
# CARD, BOARD, CHANNEL, CHANNELS, ENC, AMP, HALL_NETS, CARD_IP; POLES, COUNTS (the motor
# file's axis); $work (a folder the HAL user can read); start_sim, stop_sim, sim_ask,
# sim_reading, sim_field, sim_angle, make_hold; hal (a command in the host namespace as the HAL user); RT.
set -u

SKIP=77
HAL_USER=${I20_AXIS_TEST_USER:-nobody}

skip() {
  echo "SKIPPED: $*"
  exit $SKIP
}
fail() {
  echo "FAIL: $*"
  exit 1
}
note() { echo "${RIG_NAME:-axis_test}: $*"; }

[[ $EUID -eq 0 ]] || skip "needs root to make network namespaces (hm2_eth needs a real interface)"
if ! command -v ip >/dev/null || ! ip netns list >/dev/null 2>&1; then skip "'ip netns' is not available"; fi
if ! command -v halrun >/dev/null || ! command -v halcmd >/dev/null; then
  skip "LinuxCNC's halrun is not installed (linuxcnc-uspace)"
fi
command -v runuser >/dev/null || skip "runuser is not available"
id "$HAL_USER" >/dev/null 2>&1 || skip "no user '$HAL_USER' to run halrun as"
ls /usr/lib/linuxcnc/modules/hm2_eth.so /usr/lib/linuxcnc/modules/bldc.so >/dev/null 2>&1 ||
  skip "hm2_eth or bldc is not installed"

# The motor file's axis: servo-halls-index.yaml (4 pole pairs, 10000 counts, pattern 25).
# I20_AXIS_CARD picks the virtual card (docs/virtual-feedback.md):
#   7i92t-servo (default): channel 1 of port 0, encoder 01, Halls on GPIO 013-015;
#   7i96s: its one 8I20 (channel 0), encoder 00, Halls on the isolated inputs InM 00-02.
POLES=8
COUNTS=10000
CARD=${I20_AXIS_CARD:-7i92t-servo}
case $CARD in
  7i92t-servo)
    CHANNEL=1 ENC=01 BOARD=hm2_7i92.0 CHANNELS=2
    HALL_NETS=("$BOARD.gpio.013.in" "$BOARD.gpio.014.in" "$BOARD.gpio.015.in")
    CARD_MAC=00:60:1b:92:00:01 # the virtual 7I92T's EEPROM MAC: hm2_eth's ARP entry uses it
    ;;
  7i96s)
    CHANNEL=0 ENC=00 BOARD=hm2_7i96s.0 CHANNELS=1
    HALL_NETS=("$BOARD.inm.00.input-00" "$BOARD.inm.00.input-01" "$BOARD.inm.00.input-02")
    CARD_MAC=00:60:1b:16:00:01 # the virtual 7I96S's EEPROM MAC
    ;;
  *) echo "rig: unknown I20_AXIS_CARD '$CARD'" >&2 && exit 2 ;;
esac
CHANNELS=${I20_RIG_CHANNELS:-$CHANNELS}
AMP=$BOARD.8i20.0.$CHANNEL
# The host sits on the card's /24 at .1 (.2 when the card itself is .1).
CARD_IP=${I20_RIG_CARD_IP:-192.168.1.121}
[[ $CARD_IP =~ ^([0-9]+\.[0-9]+\.[0-9]+)\.([0-9]+)$ ]] || { echo "rig: '$CARD_IP' is not an IPv4 address" >&2 && exit 2; }
HOST_IP=${BASH_REMATCH[1]}.$([[ ${BASH_REMATCH[2]} == 1 ]] && echo 2 || echo 1)

# Both ends run SCHED_FIFO (low priority 10), as a LinuxCNC host runs its servo thread
# realtime: on a loaded machine that keeps the 1 ms thread's periods within milliseconds.
# I20_AXIS_TEST_RT="" runs them as ordinary processes.
RT=${I20_AXIS_TEST_RT-chrt -f 10}
if [[ -n $RT ]] && ! $RT true 2>/dev/null; then
  note "cannot run SCHED_FIFO here ($RT); running as ordinary processes"
  RT=""
fi
# The virtual card's own priority (I20_RIG_SIM_RT; by default as above). Even a halrun that
# runs no servo thread needs it prompt: hm2_eth's first request (the card's MAC address)
# waits for its answer about a millisecond in all (ten receives of 100 us), which a real
# card's FPGA always meets and an ordinary process on a loaded host (a sanitizer build
# beside a compiler) may not.
SIM_RT=${I20_RIG_SIM_RT-$RT}
if [[ -n $SIM_RT ]] && ! $SIM_RT true 2>/dev/null; then
  note "cannot run the virtual card SCHED_FIFO here ($SIM_RT); running it as an ordinary process"
  SIM_RT=""
fi
ns_host=i20ax-h-$$
ns_card=i20ax-c-$$
veth_host=i20h$$
veth_card=i20c$$
work=$(mktemp -d /tmp/i20-axis.XXXXXX)
chmod 755 "$work"
# rtapi_app puts its socket in $HOME (.rtapi_fifo): a home the HAL user may write.
hal_home=$work/home
mkdir "$hal_home" && chown "$HAL_USER" "$hal_home"
# The motor sits on the card's axis channel: the 7I96S has only channel 0.
if [[ $CARD == 7i96s && -n $MOTOR ]]; then
  sed 's/^channel: .*/channel: 0/' "$MOTOR" >"$work/motor.yaml"
  MOTOR=$work/motor.yaml
fi
sim_pid=""
hal_pid=""
started=$(date +%s.%N)

# shellcheck disable=SC2317  # reached through the trap
cleanup() {
  set +e
  [[ -p $work/release ]] && timeout 2 sh -c "echo > '$work/release'" 2>/dev/null
  if [[ -n $hal_pid ]] && kill -0 "$hal_pid" 2>/dev/null; then
    timeout 10 tail --pid="$hal_pid" -f /dev/null
    kill "$hal_pid" 2>/dev/null
  fi
  # rtapi_app outlives a killed halrun; halrun -U stops it and frees HAL's memory.
  ip netns exec "$ns_host" runuser -u "$HAL_USER" -- env HOME="$hal_home" timeout 20 halrun -U >/dev/null 2>&1
  # ... and only when it has gone is HAL's shared memory free for the next halrun.
  for _ in $(seq 100); do
    pgrep -x rtapi_app >/dev/null || break # setuid root: any, not the HAL user's
    sleep 0.1
  done
  if [[ -n $sim_pid ]]; then
    kill "$sim_pid" 2>/dev/null
    timeout 5 tail --pid="$sim_pid" -f /dev/null
  fi
  ip netns del "$ns_host" 2>/dev/null
  ip netns del "$ns_card" 2>/dev/null
  [[ -n ${I20_KEEP_WORK:-} ]] || rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 1' INT TERM HUP

# --- the network: host namespace <-> veth <-> card namespace ------------------------------
if ! ip netns add "$ns_host" || ! ip netns add "$ns_card"; then skip "cannot create network namespaces here"; fi
ip link add "$veth_host" type veth peer name "$veth_card" || skip "cannot create a veth pair here"
ip link set "$veth_host" netns "$ns_host"
ip link set "$veth_card" netns "$ns_card"
ip -n "$ns_card" link set "$veth_card" address "$CARD_MAC"
ip -n "$ns_host" addr add "$HOST_IP/24" dev "$veth_host"
ip -n "$ns_card" addr add "$CARD_IP/24" dev "$veth_card"
for ns in "$ns_host" "$ns_card"; do ip -n "$ns" link set lo up; done
ip -n "$ns_host" link set "$veth_host" up
ip -n "$ns_card" link set "$veth_card" up

# --- the virtual card -----------------------------------------------------------------------
start_sim() {
  mkfifo "$work/ctl"
  local -a motor=()
  [[ -n $MOTOR ]] && motor=(--motor "$MOTOR")
  $SIM_RT ip netns exec "$ns_card" "$I20SIM" --eth "$CARD_IP" --card "$CARD" --channels "$CHANNELS" "${motor[@]}" \
    --no-stdin --control "$work/ctl" >"$work/sim.out" 2>"$work/sim.err" &
  sim_pid=$!
  # Its address line says it serves: waited for while it lives (a loaded host starts it late;
  # linuxcnc_axis once found no line after a fixed 5 s here), a minute bounding one that hangs.
  local tenths=0
  until grep -q "^$CARD_IP:27181" "$work/sim.out" 2>/dev/null; do
    kill -0 "$sim_pid" 2>/dev/null || fail "i20sim did not start (it ended): $(cat "$work/sim.err")"
    ((tenths++ < 600)) || fail "i20sim did not start within a minute: $(cat "$work/sim.err")"
    sleep 0.1
  done
  # hm2_eth's first request (the card's MAC address, LBP16 command 0x4983 at 0x0002) waits
  # about a millisecond in all for its answer. Ask it once before LinuxCNC does: the host
  # learns the card's Ethernet address (ARP) and the card has run that path, so neither
  # lands in hm2_eth's millisecond on a loaded host.
  for _ in $(seq 20); do
    ip netns exec "$ns_host" bash -c "printf '\x83\x49\x02\x00' >/dev/udp/$CARD_IP/27181" 2>/dev/null
    ip -n "$ns_host" neigh show "$CARD_IP" | grep -q "lladdr" && break
    sleep 0.1
  done
  [[ -z $MOTOR ]] || grep -q "on the card's axis $CHANNEL" "$work/sim.err" || fail "the motor is not on axis $CHANNEL: $(cat "$work/sim.err")"
}
stop_sim() {
  kill "$sim_pid" 2>/dev/null
  timeout 5 tail --pid="$sim_pid" -f /dev/null
  sim_pid=""
  rm -f "$work/ctl"
}
# The simulator's answer to one control line (its stdout's next line). Every line it takes
# is answered with one, so the answer is waited for, however loaded the host (a sanitizer-built
# card under CI's load once took over the 2 s this used to wait: the question went unanswered
# and the next question read this one's answer). A card that does not answer within a minute
# fails the test, naming the question.
sim_ask() {
  local before
  before=$(wc -l <"$work/sim.out")
  echo "$1" >"$work/ctl"
  for _ in $(seq 3000); do
    (($(wc -l <"$work/sim.out") > before)) && break
    kill -0 "$sim_pid" 2>/dev/null || fail "i20sim ended before answering '$1': $(tail -n 3 "$work/sim.err")"
    sleep 0.02
  done
  (($(wc -l <"$work/sim.out") > before)) || fail "i20sim did not answer '$1' within a minute"
  tail -n +$((before + 1)) "$work/sim.out" | head -1
}
# sim_reading VAR FIELD: sets VAR to the number the motor's reading gives as FIELD=value
# (its unit cut off); fails, showing the answer, when there is none. Called as a command, not
# in $(...), so that a failure ends the test.
sim_reading() { sim_field "$1" "$2" '-\{0,1\}[0-9][0-9.]*'; }
# sim_field VAR FIELD [PATTERN]: sets VAR to FIELD's value in the motor's reading, the part
# that matches PATTERN (a sed pattern; by default a word, as output=on).
sim_field() {
  local answer value
  answer=$(sim_ask "ch $CHANNEL motor")
  value=$(sed -n "s/.* $2=\\(${3:-[a-z]*}\\).*/\\1/p" <<<" $answer")
  [[ -n $value ]] || fail "i20sim's motor reading has no $2: '$answer'"
  printf -v "$1" '%s' "$value"
}
sim_angle() { sim_reading "$1" motor_angle; }
# make_hold: writes $work/hold, a script halrun runs as `loadusr -w $work/hold NAME`: it marks
# where halrun waits ($work/marks/at-NAME, in a folder the HAL user may write), then waits for
# a line on the fifo $work/release (the caller makes it). The test waits for the mark, its event.
make_hold() {
  mkdir -p -m 1777 "$work/marks"
  # shellcheck disable=SC2016  # $1 is the hold script's own argument
  printf '#!/bin/sh\ntouch %s/at-"$1"\nread line < %s\n' "$work/marks" "$work/release" >"$work/hold"
  chmod 755 "$work/hold"
}

# --- LinuxCNC -------------------------------------------------------------------------------
hal() { $RT ip netns exec "$ns_host" runuser -u "$HAL_USER" -- env HOME="$hal_home" "$@"; }

