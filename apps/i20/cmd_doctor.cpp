// SPDX-License-Identifier: GPL-2.0-or-later
// i20 doctor [LOGFILE...] [--passive]: what LinuxCNC said about an 8I20 axis, explained.
//
// The field question is "LinuxCNC printed this; what is wrong and what do I do?". The
// matcher (lib/ops/doctor/doctor.hpp, messages in params/linuxcnc-messages.yaml) names each
// problem with the lines LinuxCNC printed, the cause, the evidence, the fix and the
// section of docs/field-messages.md it rests on, as `i20 faults` explains a fault bit.
// --passive adds the card's own state, read without disturbing the running LinuxCNC.
#include "cmd_doctor.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "faults_render.hpp"
#include "lbp/bytes.hpp"
#include "ops/doctor/doctor.hpp"
#include "ops/core/errors.hpp"
#include "ops/watch/passive_monitor.hpp"
#include "ops/scan.hpp"
#include "ops/core/timing.hpp"
#include "params/text.hpp"

namespace i20::cli {
namespace {

namespace D = i20::doctor;
namespace F = i20::faults;

struct DoctorOptions {
  std::vector<std::string> logs;
  bool passive = false;
};

std::string read_log(const std::string& path) {
  if (path == "-") return std::string(std::istreambuf_iterator<char>(std::cin), {});
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw UsageError("cannot read " + path + ": give LinuxCNC's output (halrun's, linuxcnc.log, dmesg) or -");
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) throw UsageError("cannot read " + path);
  return text.str();
}

// Words wrapped at about 96 columns, every line after the first indented by `indent`.
std::string wrapped(const std::string& text, std::size_t indent) {
  std::istringstream words(text);
  std::string out, word;
  std::size_t column = indent;
  const std::string pad(indent, ' ');
  for (bool first = true; words >> word; first = false) {
    if (!first && column + 1 + word.size() > 96) {
      out += "\n" + pad;
      column = indent;
    } else if (!first) {
      out += " ";
      ++column;
    }
    out += word;
    column += word.size();
  }
  return out;
}

std::string upper(D::Severity s) {
  switch (s) {
    case D::Severity::Error: return "ERROR";
    case D::Severity::Warning: return "WARNING";
    case D::Severity::Note: return "NOTE";
  }
  return "ERROR";
}

std::string where_said(const D::Finding& f) {
  const auto& first = f.said.front();
  std::string s = first.file + ":" + std::to_string(first.line);
  if (f.count > 1) {
    s += ", " + std::to_string(f.count) + " times";
    s += f.last_file == first.file ? ", last at line " + std::to_string(f.last_line)
                                   : ", last at " + f.last_file + ":" + std::to_string(f.last_line);
  }
  return s;
}

void print_finding(std::ostream& out, const D::Finding& f, std::size_t number) {
  out << "\n" << upper(f.severity) << " " << number << ": " << f.title << " [" << f.id << "]\n";
  out << "  LinuxCNC said (" << where_said(f) << "):\n";
  for (const auto& s : f.said) out << "    " << params::printable(s.text) << "\n";
  if (f.count > f.said.size()) out << "    ... (" << f.count - f.said.size() << " more)\n";
  out << "  evidence: " << wrapped(params::printable(f.evidence), 12) << "\n";
  out << "  cause:    " << wrapped(f.cause, 12) << "\n";
  for (std::size_t i = 0; i < f.fix.size(); ++i)
    out << (i ? "            " : "  fix:      ") << i + 1 << ". " << wrapped(params::printable(f.fix[i]), 15)
        << "\n";
  out << "  source:   " << f.docs << "\n            LinuxCNC: "
      << wrapped(f.said_by.substr(f.said_by.rfind("LinuxCNC ", 0) == 0 ? 9 : 0), 22) << "\n";
}

app::Json strings_json(const std::vector<std::string>& items) {
  auto a = app::Json::array();
  for (const auto& s : items) a.push(s);
  return a;
}

app::Json finding_json(const D::Finding& f) {
  auto j = app::Json::object();
  j.set("id", f.id).set("severity", D::to_string(f.severity)).set("title", f.title);
  auto said = app::Json::array();
  for (const auto& s : f.said)
    said.push(app::Json::object()
                  .set("file", s.file)
                  .set("line", static_cast<long long>(s.line))
                  .set("text", s.text));
  j.set("said", std::move(said)).set("count", static_cast<long long>(f.count));
  j.set("last",
        app::Json::object().set("file", f.last_file).set("line", static_cast<long long>(f.last_line)));
  j.set("evidence", f.evidence).set("cause", f.cause).set("fix", strings_json(f.fix));
  j.set("docs", f.docs).set("said_by", f.said_by);
  return j;
}

// ------------------------------------------------------------------ the card, passively
struct CardState {
  bool asked = false;
  std::string describe, error, host;
  std::vector<ops::PassiveAmplifier> amplifiers;
  std::size_t problems = 0;  // latched faults, 8I20s out of the host's cycle
};

CardState read_card(Context& ctx) {
  CardState c;
  c.asked = true;
  const auto host_port = ops::ethernet_host_port(ctx.options.target);
  if (!host_port)
    throw UsageError(
        "doctor --passive reads the card LinuxCNC is running through its Ethernet card: give the card's "
        "address, e.g. i20 --eth 192.168.1.121 doctor linuxcnc.log --passive");
  try {
    ops::PassiveMonitor monitor(*host_port, {.read = ops::timing::passive(ctx.options.link)});
    c.describe = monitor.describe();
    monitor.sample();  // the second sample knows whether a host is talking
    const auto s = monitor.sample();
    const auto active = s.host_active();
    c.host =
        !active ? "unknown"
        : *active
            ? "LinuxCNC (or another host) is running the card"
            : "no host talked to the card between two reads: the values are the last LinuxCNC left (stale)";
    c.amplifiers = s.amplifiers;
    for (const auto& a : c.amplifiers) c.problems += (!a.data.live() || a.data.fault() != 0);
  } catch (const UsageError&) {
    throw;
  } catch (const std::exception& e) {
    c.error = e.what();
    c.problems = 1;
  }
  return c;
}

std::string fixed(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

void print_card(std::ostream& out, const CardState& c) {
  out << "\nThe card, read passively (nothing written, nothing stopped)";
  if (!c.error.empty()) {
    out << ": not reached: " << c.error << "\n";
    return;
  }
  out << ": " << c.describe << "; " << c.host << "\n";
  if (c.amplifiers.empty()) out << "  no 8I20 on any smart-serial channel\n";
  for (const auto& a : c.amplifiers) {
    const auto& d = a.data;
    out << "\n8I20 " << a.linuxcnc_name << " (" << a.target << "): ";
    if (!d.live()) {
      out << "NOT in LinuxCNC's cycle (" << a.link_status
          << "): its port is stopped or the 8I20 does not answer; see the findings above\n";
      continue;
    }
    out << "bus " << fixed(d.busv_v()) << " V, " << d.temperature_c() << " degC, FAULT "
        << lbp::hex_value(d.fault(), 4) << ", STATUS " << lbp::hex_value(d.status(), 4) << "\n";
    if (d.fault() == 0) continue;
    print_fault_report(out, F::fault_report(d.fault()));
  }
}

app::Json card_json(const CardState& c) {
  auto j = app::Json::object();
  j.set("card", c.describe).set("reached", c.error.empty());
  if (!c.error.empty()) return j.set("error", c.error);
  j.set("host", c.host);
  auto amps = app::Json::array();
  for (const auto& a : c.amplifiers) {
    const auto& d = a.data;
    auto aj = app::Json::object();
    aj.set("linuxcnc_name", a.linuxcnc_name).set("target", a.target).set("live", d.live());
    aj.set("link_status", a.link_status).set("busv_v", d.busv_v()).set("temperature_c", d.temperature_c());
    aj.set("fault", static_cast<unsigned>(d.fault())).set("status", static_cast<unsigned>(d.status()));
    aj.set("fault_report", report_json(F::fault_report(d.fault()), &a.readings));
    amps.push(std::move(aj));
  }
  return j.set("amplifiers", std::move(amps));
}

// ------------------------------------------------------------------ doctor
void run_doctor(Context& ctx, const DoctorOptions& o) {
  if (o.logs.empty() && !o.passive)
    throw UsageError(
        "give LinuxCNC's output to read: i20 doctor linuxcnc.log (halrun's output, ~/linuxcnc_debug.txt, "
        "dmesg, "
        "or - for standard input), and/or --passive with --eth IP to read the running card");
  std::vector<D::LogLine> lines;
  for (const auto& path : o.logs) {
    auto more = D::split_lines(read_log(path), path == "-" ? "stdin" : path);
    lines.insert(lines.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  }
  const auto d = D::diagnose(lines);
  CardState card;
  if (o.passive) card = read_card(ctx);
  const std::size_t problems = d.problems() + card.problems;
  // A checker's codes, as `i20 profile diff` and `i20 hal lint`: 1 found something, 2 could
  // not look (here: the card not reached).
  if (problems > 0) ctx.record(ops::Comparison::Differs);
  if (!card.error.empty()) ctx.record(ops::Comparison::Trouble);

  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("files", strings_json(o.logs)).set("lines", static_cast<long long>(d.lines));
    j.set("known_lines", static_cast<long long>(d.known)).set("problems", static_cast<long long>(problems));
    auto findings = app::Json::array();
    for (const auto& f : d.findings) findings.push(finding_json(f));
    j.set("findings", std::move(findings));
    auto unknown = app::Json::array();
    for (const auto& u : d.unrecognised)
      unknown.push(app::Json::object()
                       .set("file", u.first.file)
                       .set("line", static_cast<long long>(u.first.line))
                       .set("text", u.first.text)
                       .set("count", static_cast<long long>(u.count)));
    j.set("unrecognised", std::move(unknown));
    j.set("card", card.asked ? card_json(card) : app::Json());
    ctx.print_json(j);
    return;
  }

  auto& out = std::cout;
  if (!o.logs.empty()) {
    const std::size_t notes = d.findings.size() - d.problems();
    out << "LinuxCNC's output: " << d.lines << " line" << (d.lines == 1 ? "" : "s") << " read, "
        << d.problems() << " problem" << (d.problems() == 1 ? "" : "s") << ", " << notes << " note"
        << (notes == 1 ? "" : "s") << ", " << d.known << " normal line" << (d.known == 1 ? "" : "s")
        << " of the driver recognised\n";
    for (std::size_t i = 0; i < d.findings.size(); ++i) print_finding(out, d.findings[i], i + 1);
    if (!d.unrecognised.empty()) {
      out << "\nNot recognised: " << d.unrecognised.size() << " line"
          << (d.unrecognised.size() == 1 ? "" : "s")
          << " about the card that i20 doctor has no explanation for (read them yourself; they may "
             "matter):\n";
      for (const auto& u : d.unrecognised)
        out << "  " << u.first.file << ":" << u.first.line
            << (u.count > 1 ? " (" + std::to_string(u.count) + " times)" : "") << ": "
            << params::printable(u.first.text) << "\n";
    }
    if (d.findings.empty() && d.unrecognised.empty())
      out << "\nNothing LinuxCNC said about the card points at a problem.\n";
  }
  if (card.asked) print_card(out, card);
  if (problems == 0 && card.asked && o.logs.empty()) out << "\nNo fault latched on any 8I20 of the card.\n";
}

}  // namespace

void register_doctor_command(CLI::App& app, Context& ctx) {
  auto o = std::make_shared<DoctorOptions>();
  auto* doctor = app.add_subcommand(
      "doctor",
      "Explain what LinuxCNC said about an 8I20 axis: give it LinuxCNC's own output (halrun's terminal, "
      "linuxcnc.log or ~/linuxcnc_debug.txt, dmesg, a `halcmd show pin` table) and it names each problem "
      "with "
      "the lines LinuxCNC printed, the cause, the evidence, the fix and the section of "
      "docs/field-messages.md "
      "it rests on: the 8I20 faulting while the bus rises at power-up, a servo thread that runs late (DoIt "
      "not cleared), the smart-serial error counter stopping the port (Smart Serial Comms Error, restarted "
      "only "
      "by toggling its run pin), remote faults reported once and latched, hm2_eth's packet errors and "
      "io-error "
      "on a lossy link. Repeated lines are counted once; lines about the card it does not know are listed as "
      "not recognised. With --passive (and --eth IP) it adds the card's own state, read without disturbing "
      "LinuxCNC: every 8I20's latched faults and bus voltage, explained as `i20 faults` does");
  doctor
      ->add_option("LOGFILE", o->logs,
                   "LinuxCNC's output; - reads standard input (several files: read in order)")
      ->type_name("FILE");
  doctor->add_flag(
      "--passive", o->passive,
      "Also read the running card through its Ethernet card (--eth IP) without writing, starting or "
      "stopping anything: each 8I20's FAULT, STATUS and bus voltage from LinuxCNC's last cycle");
  doctor->footer(
      "Exit 0 when nothing points at a problem (notes, such as a non-realtime kernel, do not count), 1 when "
      "there are findings, 2 when a file cannot be read or --passive did not reach the card. --json gives "
      "every "
      "finding with its lines. Examples:\n"
      "  halrun -f axis.hal 2>&1 | tee hal.out; i20 doctor hal.out\n"
      "  dmesg | i20 doctor -\n"
      "  i20 --eth 192.168.1.121 doctor ~/linuxcnc_debug.txt --passive\n"
      "Every explanation rests on a section of docs/field-messages.md in i20tools' source.");
  doctor->callback([&ctx, o] { run_doctor(ctx, *o); });
}

}  // namespace i20::cli
