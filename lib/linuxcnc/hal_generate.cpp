// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/hal_generate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>
#include <sstream>

#include "error/error.hpp"
#include "linuxcnc/index_capture.hpp"
#include "params/param_db.hpp"

namespace i20::linuxcnc {
namespace {

// LinuxCNC's logic component takes at most 16 inputs per gate (logic(9)).
constexpr int kLogicMaxInputs = 16;
// Personality bits of logic(9): the outputs a gate has.
constexpr unsigned kLogicAnd = 0x100, kLogicOr = 0x200, kLogicNand = 0x800, kLogicNor = 0x1000;

// hostmot2's default fault-lim for a smart-serial port (sserial(9); its "Smart Serial Comms
// Error" message says "at least 200 times").
constexpr int kSserialFaultLimit = 200;

std::string two_digits(int n) {
  std::string digits = n < 10 ? "0" : "";  // apart: GCC 12's -O3 -Wrestrict misfires on `"0" + std::string&&`
  digits += std::to_string(n);
  return digits;
}

std::string hex(unsigned v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%X", v);
  return buf;
}

std::string amps(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

bool has(const std::string& cfg, char letter) {
  return cfg.find(letter) != std::string::npos;
}

std::string sorted_letters(std::string cfg) {
  std::sort(cfg.begin(), cfg.end());
  return cfg;
}

bool is_hal_name(const std::string& name) {
  static const std::regex kName(R"(^[A-Za-z0-9_][A-Za-z0-9_.\-]*[A-Za-z0-9_\-]$)");
  return std::regex_match(name, kName) && name.find("..") == std::string::npos;
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(item);
  return out;
}

double card_max_current() {
  const auto db = params::ParamDb::builtin();
  const auto& p = db.get("MAXCURRENT");
  return static_cast<double>(p.max) * p.scale;
}

void check_board(const HalPlan& plan) {
  (void)hm2_device(plan.board);
  static const std::regex kIp(
      R"(^(25[0-5]|2[0-4][0-9]|1?[0-9]?[0-9])(\.(25[0-5]|2[0-4][0-9]|1?[0-9]?[0-9])){3}$)");
  if (!std::regex_match(plan.board_ip, kIp))
    throw UsageError("--board-ip " + plan.board_ip +
                     " is not an IPv4 address (the 7I96S/7I92T default is 10.10.10.10)");
}

void check_cfg(const HalPlan& plan, const HalNames& names) {
  const std::string letters = sorted_letters(plan.cfg);
  if (letters != "hq" && letters != "hiq" && letters != "h")
    throw UsageError(
        "--cfg " + plan.cfg +
        ": i20 hal writes qh, qhi or h. q and qi align by driving bldc's own phase outputs, which an 8I20 "
        "fed from bldc's out does not get; a needs an absolute encoder");
  if (plan.axes < 1 || plan.axes > names.bldc_max_instances())
    throw UsageError("--axes " + std::to_string(plan.axes) + ": 1 to " +
                     std::to_string(names.bldc_max_instances()) + " (one bldc makes at most " +
                     std::to_string(names.bldc_max_instances()) + " instances)");
}

void check_motor(const HalPlan& plan) {
  const bool halls = has(plan.cfg, 'h'), encoder = has(plan.cfg, 'q'), index = has(plan.cfg, 'i');
  if (halls && !plan.pattern)
    throw UsageError("--pattern is required with cfg=" + plan.cfg + " (the Halls' pattern, 0-47)");
  if (!halls && plan.pattern)
    throw UsageError("--pattern is for a cfg with Halls (h); cfg=" + plan.cfg + " has none");
  if (plan.pattern && (*plan.pattern < 0 || *plan.pattern > 47))
    throw UsageError("--pattern " + std::to_string(*plan.pattern) + ": bldc's Hall patterns are 0 to 47");
  if (encoder && !plan.poles)
    throw UsageError("--poles is required with cfg=" + plan.cfg + " (motor poles, not pole pairs)");
  if (plan.poles && (*plan.poles < 2 || *plan.poles % 2 != 0))
    throw UsageError("--poles " + std::to_string(*plan.poles) +
                     ": the number of poles is even and at least 2 (pole pairs x 2)");
  if (encoder && !plan.counts_per_rev)
    throw UsageError("--counts-per-rev is required with cfg=" + plan.cfg +
                     " (encoder counts per motor revolution)");
  if (plan.counts_per_rev && *plan.counts_per_rev == 0)
    throw UsageError(
        "--counts-per-rev 0: give the encoder's counts per motor revolution (negative reverses commutation)");
  if (!encoder && (plan.poles || plan.counts_per_rev))
    throw UsageError("--poles and --counts-per-rev are for a cfg with an encoder (q); cfg=" + plan.cfg +
                     " has none");
  if (index && !plan.encoder_offset)
    throw UsageError("--encoder-offset is required with cfg=" + plan.cfg +
                     " (counts from the index to electrical zero)");
  if (!index && plan.encoder_offset)
    throw UsageError("--encoder-offset needs a cfg with i: bldc cfg=" + plan.cfg +
                     " creates no encoder-offset");
}

void check_pins(const HalPlan& plan) {
  const bool halls = has(plan.cfg, 'h');
  if (halls && static_cast<int>(plan.halls.size()) != plan.axes)
    throw UsageError("--halls: give one --halls A,B,C per axis (" + std::to_string(plan.axes) + "), " +
                     std::to_string(plan.halls.size()) + " given");
  if (!halls && !plan.halls.empty())
    throw UsageError("--halls is for a cfg with Halls (h); cfg=" + plan.cfg + " has none");
  for (const auto& set : plan.halls) {
    const auto pins = split_commas(set);
    if (pins.size() != 3) throw UsageError("--halls " + set + ": three pins, comma-separated (Hall 1, 2, 3)");
    for (const auto& pin : pins)
      if (!is_hal_name(pin)) throw UsageError("--halls: '" + pin + "' is not a HAL pin name");
  }
  if (!plan.estop_in.empty() && !is_hal_name(plan.estop_in))
    throw UsageError("--estop-in: '" + plan.estop_in + "' is not a HAL pin name");
}

// One axis's names.
struct Axis {
  int k = 0;
  std::string joint, i20, encoder, bldc, pid, faults, sig;
};

// The biquad after pid k (HalPlan::notch).
std::string notch_name(int k) {
  std::string name = "i20-notch-";
  return name.append(std::to_string(k));
}

Axis axis(const std::string& board, int k) {
  const std::string n = std::to_string(k);
  return {k,           "joint." + n, board + ".8i20.0." + n, board + ".encoder." + two_digits(k),
          "bldc." + n, "pid." + n,   "i20-faults-" + n,      "j" + n + "-"};
}

void header(std::ostream& out, const HalPlan& plan, const std::string& board) {
  const bool encoder = has(plan.cfg, 'q');
  out << "# LinuxCNC HAL file for " << plan.axes << " Mesa 8I20 axis" << (plan.axes == 1 ? "" : "es")
      << " on a " << (plan.board == "7i96s" ? "7I96S" : "7I92T") << " (" << board
      << "), written by i20 hal.\n";
  if (!plan.command_line.empty()) out << "#   " << plan.command_line << "\n";
  out << "#\n"
         "# Axis k: the 8I20 on smart-serial port 0 channel k, encoder k, bldc.k (cfg="
      << plan.cfg
      << "), pid.k, joint.k.\n"
         "# The pid closes the position loop and its output is the 8I20 current in amps (hostmot2 scales\n"
         "# `current` from the card's MAXCURRENT), limited to MAXCURRENT "
      << amps(*plan.max_current)
      << " A. bldc's rotor-angle feeds the\n"
         "# 8I20's angle: the 8I20 adds its own lead, so phase-angle (rotor-angle plus lead-angle) is not "
         "used.\n"
         "# hostmot2 has no 8I20 enable pin: torque is off while the pid is disabled (output 0), and the\n"
         "# 8I20's isolated enable input (TB1 pins 3/4) must be wired to the machine's enable.\n";
  if (plan.axes > 1)
    out << "# More than one axis needs firmware with that many smart-serial channels and encoders (the\n"
           "# 7I96S's own connectors have one of each).\n";
  out << "#\n"
         "# INI values this file reads:\n"
         "#   [KINS]KINEMATICS, [KINS]JOINTS            kinematics module and joint count\n"
         "#   [EMCMOT]EMCMOT, [EMCMOT]SERVO_PERIOD      motion module and servo period (ns)\n"
         "#   [JOINT_k]ENCODER_SCALE                    encoder counts per machine unit (joint k)\n"
         "#   [JOINT_k]P, I, D, FF0, FF1, FF2, BIAS, DEADBAND\n"
         "#                                             pid gains of joint k; the output is in amps, so\n"
         "#                                             P is amps per machine unit of following error\n"
         "#   [JOINT_k]FERROR, MIN_FERROR               following-error limits (motion reads them itself)\n";
  if (plan.notch)
    out << "#   [JOINT_k]NOTCH_N0, NOTCH_N1, NOTCH_N2, NOTCH_D1, NOTCH_D2\n"
           "#                                             the notch after pid k (i20 pid --notch): "
           "LinuxCNC's\n"
           "#                                             biquad with these coefficients (its type 0)\n";
  if (encoder)
    out << "# Motor: " << *plan.poles << " poles, " << *plan.counts_per_rev
        << " encoder counts per revolution"
        << (plan.encoder_offset ? ", encoder-offset " + std::to_string(*plan.encoder_offset) : std::string())
        << ".\n";
  if (plan.pattern) out << "# Hall pattern " << *plan.pattern << ".\n";
  out << "\n";
}

// One index capture per axis (index_capture.hpp), named after the axis's signals.
std::vector<IndexCapture> captures(const HalPlan& plan) {
  std::vector<IndexCapture> out;
  for (int k = 0; k < plan.axes; ++k) {
    std::string prefix = "j";  // append(): GCC 12's -O3 -Wrestrict misfires on operator+
    prefix.append(std::to_string(k)).append("-");
    out.push_back(index_capture(prefix, k));
  }
  return out;
}

void load_section(std::ostream& out, const HalPlan& plan, const std::string& board, const HalNames& names) {
  std::string cfgs, logic_names, personalities;
  const auto gate = [&](const std::string& name, unsigned personality) {
    logic_names.append(name).append(",");
    personalities.append(hex(personality)).append(",");
  };
  for (int k = 0; k < plan.axes; ++k) {
    const std::string n = std::to_string(k);
    cfgs += (k ? "," : "") + plan.cfg;
    gate("i20-faults-" + n, kLogicOr | static_cast<unsigned>(names.i20_fault_pins().size()));
    gate("i20-ok-" + n, kLogicNand | 2u);
    gate("i20-enable-" + n, kLogicAnd | 2u);
  }
  gate("i20-link-ok", kLogicNor | 2u);
  gate("i20-estop-ok", kLogicAnd | static_cast<unsigned>(plan.axes + 2));
  logic_names.pop_back();
  personalities.pop_back();
  out << "# ---- components\n"
         "loadrt [KINS]KINEMATICS\n"
         "loadrt [EMCMOT]EMCMOT servo_period_nsec=[EMCMOT]SERVO_PERIOD num_joints=[KINS]JOINTS\n"
         "loadrt hostmot2\n"
         "loadrt hm2_eth board_ip="
      << plan.board_ip << "\n"
      << "loadrt pid num_chan=" << plan.axes << "\n"
      << "loadrt bldc cfg=" << cfgs << "\n";
  if (plan.notch) {
    std::string notches;
    for (int k = 0; k < plan.axes; ++k) notches.append(k ? "," : "").append(notch_name(k));
    out << "loadrt biquad names=" << notches << "\n";
  }
  const auto index_captures = has(plan.cfg, 'i') ? captures(plan) : std::vector<IndexCapture>{};
  out << index_capture_loads(index_captures);
  out << "# Per axis: any fault of its 8I20 (or), that fault while the port is watched (nand: ok), and\n"
         "# the pid's enable while the port is watched (and); the link's failure (nor: ok); and one gate\n"
         "# that lets the machine out of E-stop only while the E-stop loop is closed, no watched 8I20 has\n"
         "# a fault and the link holds.\n"
         "loadrt logic names="
      << logic_names << " personality=" << personalities << "\n"
      << "# The power-up: the port runs a while after machine-on, its faults are watched a while later.\n"
         "loadrt timedelay names=i20-port-run,i20-watching\n"
         "# The port's error counter against hostmot2's limit (the link's failure, below).\n"
         "loadrt conv_u32_float names=i20-port-errors\n"
         "loadrt comp names=i20-port-stopped\n\n"
      << "addf " << board << ".read servo-thread\n"
      << "addf motion-command-handler servo-thread\n"
         "addf motion-controller servo-thread\n";
  out << "addf i20-port-run servo-thread\naddf i20-watching servo-thread\n";
  for (int k = 0; k < plan.axes; ++k)
    out << "addf i20-faults-" << k << " servo-thread\naddf i20-ok-" << k << " servo-thread\naddf i20-enable-"
        << k << " servo-thread\n";
  out << "addf i20-port-errors servo-thread\naddf i20-port-stopped servo-thread\naddf i20-link-ok "
         "servo-thread\naddf i20-estop-ok servo-thread\n";
  for (int k = 0; k < plan.axes; ++k) {
    out << "addf pid." << k << ".do-pid-calcs servo-thread\n";
    if (plan.notch) out << "addf " << notch_name(k) << " servo-thread\n";
  }
  for (const auto& capture : index_captures) out << index_capture_functions(capture);
  for (int k = 0; k < plan.axes; ++k) out << "addf bldc." << k << " servo-thread\n";
  out << "addf " << board << ".write servo-thread\n\n";
}

// HAL's timedelay takes seconds.
double seconds(std::chrono::milliseconds delay) {
  return std::chrono::duration<double>(delay).count();
}

void smart_serial_section(std::ostream& out, const std::string& board, const PowerUpDelays& delays) {
  out << "# ---- smart-serial port 0: power-up and fault reset\n"
         "# The port runs only while the machine is on, from "
      << seconds(delays.port_run)
      << " s after machine-on: the 8I20s' bus has risen by\n"
         "# then, so a normal power-up latches no bus fault. Machine off stops the port (no DoIt: the\n"
         "# 8I20's 40 ms watchdog turns its output off); the next machine-on starts it again, which is\n"
         "# how hostmot2 clears a stopped port and its remotes' latched faults (sserial(9): run low, then\n"
         "# high). The 8I20s' faults count "
      << seconds(delays.fault_watch)
      << " s after the start, so the stopped port's stale ones never hold\n"
         "# the machine in E-stop, and the pids are enabled only then.\n"
      << "setp i20-port-run.on-delay " << seconds(delays.port_run) << "\n"
      << "setp i20-port-run.off-delay 0\n"
      << "setp i20-watching.on-delay " << seconds(delays.fault_watch) << "\n"
      << "setp i20-watching.off-delay 0\n"
      << "net i20-machine-on motion.motion-enabled => i20-port-run.in\n"
      << "net i20-port-run i20-port-run.out => " << board << ".sserial.port-0.run i20-watching.in\n"
      << "net i20-watching i20-watching.out\n"
      << "# The link: hm2_eth's packet errors past their limit (io-error) stop the machine.\n"
      << "net i20-link-failed " << board << ".packet-error-exceeded => i20-link-ok.in-00\n"
      << "# So does a port hostmot2 stopped for its errors (Smart Serial Comms Error): when its\n"
      << "# fault-count passes fault-lim, hostmot2 stops the port, whose 8I20s' fault pins then stop\n"
      << "# updating, and the count keeps its value until the port starts again (sserial(9)). The\n"
      << "# comparison's limit is fault-lim's: change both together.\n"
      << "setp " << board << ".sserial.port-0.fault-lim " << kSserialFaultLimit << "\n"
      << "setp i20-port-stopped.in0 " << kSserialFaultLimit << "\n"
      << "net i20-port-errors " << board << ".sserial.port-0.fault-count => i20-port-errors.in\n"
      << "net i20-port-error-count i20-port-errors.out => i20-port-stopped.in1\n"
      << "net i20-port-stopped i20-port-stopped.out => i20-link-ok.in-01\n\n";
}

void axis_section(std::ostream& out, const HalPlan& plan, const Axis& a, const HalNames& names) {
  const std::string n = std::to_string(a.k);
  const std::string ini = "[JOINT_" + n + "]";
  out << "# ---- axis " << n << ": " << a.i20 << ", " << a.encoder << ", " << a.bldc << ", " << a.pid << "\n"
      << "setp " << a.encoder << ".scale " << ini << "ENCODER_SCALE\n"
      << "net " << a.sig << "pos-fb " << a.encoder << ".position => " << a.pid << ".feedback " << a.joint
      << ".motor-pos-fb\n"
      << "net " << a.sig << "pos-cmd " << a.joint << ".motor-pos-cmd => " << a.pid << ".command\n"
      << "net " << a.sig << "amp-enable " << a.joint << ".amp-enable-out => i20-enable-" << n << ".in-00\n"
      << "net i20-watching => i20-enable-" << n << ".in-01\n"
      << "net " << a.sig << "enable i20-enable-" << n << ".and => " << a.pid << ".enable\n\n"
      << "# Position loop; its output is the current command in amps.\n";
  for (const char* gain : {"P", "I", "D", "FF0", "FF1", "FF2", "BIAS", "DEADBAND"}) {
    const std::string param = std::string(gain) == "P"          ? "Pgain"
                              : std::string(gain) == "I"        ? "Igain"
                              : std::string(gain) == "D"        ? "Dgain"
                              : std::string(gain) == "BIAS"     ? "bias"
                              : std::string(gain) == "DEADBAND" ? "deadband"
                                                                : gain;
    out << "setp " << a.pid << "." << param << " " << ini << gain << "\n";
  }
  out << "setp " << a.pid << ".maxoutput " << amps(*plan.max_current) << "   # amps: the card's MAXCURRENT\n";
  if (plan.notch) {
    const std::string notch = notch_name(a.k);
    out << "# The notch after the pid (i20 pid --notch designed the loop with it): type 0 takes the\n"
           "# coefficients as given; enabling it (a rising enable) makes them its own.\n"
        << "setp " << notch << ".type 0\n";
    for (const auto& [param, key] :
         {std::pair{"n0", "NOTCH_N0"}, std::pair{"n1", "NOTCH_N1"}, std::pair{"n2", "NOTCH_N2"},
          std::pair{"d1", "NOTCH_D1"}, std::pair{"d2", "NOTCH_D2"}})
      out << "setp " << notch << "." << param << " " << ini << key << "\n";
    out << "setp " << notch << ".enable 1\n"
        << "net " << a.sig << "torque-raw " << a.pid << ".output => " << notch << ".in\n"
        << "net " << a.sig << "torque " << notch << ".out => " << a.bldc << ".value\n\n";
  } else {
    out << "net " << a.sig << "torque " << a.pid << ".output => " << a.bldc << ".value\n\n";
  }
  out << "# Commutation: bldc turns the command into the rotor angle and a signed current.\n";
  if (has(plan.cfg, 'q')) {
    if (!has(plan.cfg, 'i'))
      out << "net " << a.sig << "rawcounts " << a.encoder << ".rawcounts => " << a.bldc << ".rawcounts\n";
    out << "setp " << a.bldc << ".scale " << *plan.counts_per_rev << "\n"
        << "setp " << a.bldc << ".poles " << *plan.poles << "\n";
  }
  if (has(plan.cfg, 'i')) {
    out << "# bldc arms the index at start-up and takes its offset from the first index; the encoder\n"
           "# resets its position there, so the joint's position jumps once before homing. Do not share\n"
           "# this signal with "
        << a.joint << ".index-enable.\n"
        << "net " << a.sig << "bldc-index " << a.encoder << ".index-enable <=> " << a.bldc
        << ".index-enable\n"
        << "setp " << a.bldc << ".encoder-offset " << *plan.encoder_offset << "\n"
        << index_capture_nets(index_capture(a.sig, a.k), a.encoder, a.bldc, a.sig, a.sig + "bldc-index");
  }
  if (has(plan.cfg, 'h')) {
    const auto pins = split_commas(plan.halls.at(static_cast<std::size_t>(a.k)));
    for (int h = 0; h < 3; ++h)
      out << "net " << a.sig << "hall" << h + 1 << " " << pins[static_cast<std::size_t>(h)] << " => "
          << a.bldc << ".hall" << h + 1 << "\n";
    out << "setp " << a.bldc << ".pattern " << *plan.pattern << "\n";
  }
  out << "net " << a.sig << "rotor-angle " << a.bldc << ".rotor-angle => " << a.i20 << ".angle\n"
      << "net " << a.sig << "current " << a.bldc << ".out => " << a.i20 << ".current\n\n"
      << "# Every fault pin of this 8I20 into its gate.\n";
  int in = 0;
  for (const auto& fault : names.i20_fault_pins()) {
    std::string signal = fault;
    std::replace(signal.begin(), signal.end(), '.', '-');
    out << "net " << a.sig << "8i20-" << signal << " " << a.i20 << "." << fault << " => " << a.faults
        << ".in-" << two_digits(in++) << "\n";
  }
  out << "net " << a.sig << "8i20-fault " << a.faults << ".or => i20-ok-" << a.k << ".in-00\n"
      << "net i20-watching => i20-ok-" << a.k << ".in-01\n"
      << "net " << a.sig << "8i20-ok i20-ok-" << a.k << ".nand => i20-estop-ok.in-" << two_digits(a.k + 1)
      << "\n\n";
}

void estop_section(std::ostream& out, const HalPlan& plan) {
  out << "# ---- E-stop chain\n";
  if (plan.estop_in.empty())
    out << "# estop-ext is true while the E-stop loop is closed. Nothing drives it here: net your E-stop\n"
           "# input to it (net estop-ext <pin>), or the machine stays in E-stop.\n"
           "net estop-ext => i20-estop-ok.in-00\n";
  else
    out << "net estop-ext " << plan.estop_in << " => i20-estop-ok.in-00\n";
  out << "net i20-link-ok i20-link-ok.nor => i20-estop-ok.in-" << two_digits(plan.axes + 1) << "\n"
      << "net estop-ok i20-estop-ok.and => iocontrol.0.emc-enable-in\n"
         "# A latched 8I20 fault holds E-stop only while the port runs: in E-stop the machine is off and\n"
         "# the port stopped, so E-stop can be reset; machine-on starts the port again, which clears the\n"
         "# fault, or trips again while its cause remains.\n\n"
         "# ---- tool changes (no tool changer: confirm at once)\n"
         "net tool-change-loop iocontrol.0.tool-change => iocontrol.0.tool-changed\n"
         "net tool-prepare-loop iocontrol.0.tool-prepare => iocontrol.0.tool-prepared\n";
}

}  // namespace

std::string hm2_device(const std::string& board) {
  if (board == "7i96s") return "hm2_7i96s.0";
  if (board == "7i92t") return "hm2_7i92.0";  // hm2_eth names the 7I92T like the 7I92
  throw UsageError("--board " + board + ": 7i96s or 7i92t");
}

void check_plan(const HalPlan& plan, const HalNames& names) {
  check_board(plan);
  check_cfg(plan, names);
  check_motor(plan);
  if (!plan.max_current)
    throw UsageError("--max-current (or --profile) is required: the card's MAXCURRENT in amps");
  const double card_max = card_max_current();
  if (!(*plan.max_current > 0) || *plan.max_current > card_max)
    throw UsageError("--max-current " + amps(*plan.max_current) +
                     ": the 8I20's MAXCURRENT is above 0 and at most " + amps(card_max) + " A");
  check_pins(plan);
  if (static_cast<int>(names.i20_fault_pins().size()) > kLogicMaxInputs || plan.axes + 1 > kLogicMaxInputs)
    throw UsageError("too many inputs for one logic gate (at most 16)");
}

std::string generate_hal(const HalPlan& plan, const PowerUpDelays& delays, const HalNames& names) {
  check_plan(plan, names);
  const std::string board = hm2_device(plan.board);
  std::ostringstream out;
  header(out, plan, board);
  load_section(out, plan, board, names);
  smart_serial_section(out, board, delays);
  for (int k = 0; k < plan.axes; ++k) axis_section(out, plan, axis(board, k), names);
  estop_section(out, plan);
  return out.str();
}

}  // namespace i20::linuxcnc
