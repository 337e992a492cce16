// SPDX-License-Identifier: GPL-2.0-or-later
// i20 faults | faults decode | faults mask | clear-faults (watch: cmd_watch.cpp)
//
// The field question is "why did the axis drop out, and what do I check?": every command
// here names each set bit, says what it means, what usually causes it and what to check,
// and, with a card attached, whether the cause is still there right now.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

#include "change_render.hpp"
#include "context.hpp"
#include "faults/fault_mask.hpp"
#include "faults/register_spec.hpp"
#include "faults/register_value.hpp"
#include "faults_render.hpp"
#include "lbp/bytes.hpp"
#include "ops/core/errors.hpp"
#include "ops/core/timing.hpp"
#include "ops/faults.hpp"
#include "ops/watch/live_source.hpp"
#include "passive.hpp"

namespace i20::cli {
namespace {

namespace F = i20::faults;

// lib/faults raises its own error types; the apps' exit codes are about what happened to
// the card, so map them: a bad value or name is bad input (2), an unmaskable bit is a
// refusal (3). Both are raised before anything is sent.
template <class Fn>
void with_fault_errors_mapped(Fn&& fn) {
  try {
    fn();
  } catch (const F::BadRegisterValue& e) {
    throw UsageError(e.what());
  } catch (const F::UnknownBit& e) {
    throw UsageError(e.what());
  } catch (const F::NotMaskable& e) {
    throw ops::SafetyError(std::string(e.what()) + "; nothing was written");
  }
}

std::string readings_line(const Readings& r) {
  std::string line = "FAULT " + lbp::hex_value(r.fault, 4) + ", STATUS " + lbp::hex_value(r.status, 4);
  if (r.faultmask) line += ", FAULTMASK " + lbp::hex_value(*r.faultmask, 4);
  char buf[96];
  if (r.busv_v) {
    std::snprintf(buf, sizeof buf, "; bus %.2f V", *r.busv_v);
    line += buf;
  }
  if (r.temperature_c) {
    std::snprintf(buf, sizeof buf, ", card %.2f degC", *r.temperature_c);
    line += buf;
  }
  return line + ", brake " + (brake_on(r) ? "on" : "off");
}

// ------------------------------------------------------------------ faults (live)
void print_next_step(const F::Report& fault, const F::Report& status, const std::string& flags) {
  // "No faults" is not all there is to say while a STATUS warning stands (the brake resistor
  // on at a supply above BRAKEONV burns it out without any fault).
  for (const auto& line : status.lines)
    if (line.severity != F::Impact::Info)
      std::cout << "\nWARNING: " << bit_label(line) << ": " << line.meaning
                << (line.evidence.empty() ? "" : " (" + line.evidence + ")") << "\n";
  if (fault.value == 0) {
    std::cout << "\nNo faults latched.\n";
    return;
  }
  std::cout << "\nNext: fix the causes above, then run `i20 " << flags
            << " clear-faults` (it reports anything that cannot clear yet).\n";
}

// Register reads on every transport (Ethernet included: the setup-mode passthrough), so a
// latched fault is reported as it is; SSLBP's normal start would clear it.
void run_faults(Context& ctx) {
  const auto source = ops::make_live_source(ctx.session(), ops::LiveMode::Registers);
  const Readings r = source->read();
  const auto fault = F::fault_report(r.fault, r.faultmask);
  const auto status = live_status_report(r);
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("source", "card").set("target", source->describe()).set("method", source->method());
    j.set("fault", report_json(fault, &r)).set("status", report_json(status));
    j.set("readings", readings_json(r));
    ctx.print_json(j);
    return;
  }
  std::cout << "8I20 on " << source->describe() << ": " << readings_line(r) << "\n\n";
  RenderOptions options;
  options.live = &r;
  options.clear_command = "i20 " + ctx.target_flags() + " clear-faults";
  print_fault_report(std::cout, fault, options);
  std::cout << "\n";
  print_status_report(std::cout, status);
  print_next_step(fault, status, ctx.target_flags());
}

// ------------------------------------------------------------------ faults decode
struct DecodeOptions {
  std::string fault;
  std::string status;
  std::string mask;
};

void run_decode(Context& ctx, const DecodeOptions& o) {
  if (o.fault.empty() && o.status.empty())
    throw UsageError("give a FAULT value (e.g. `i20 faults decode 0x0102`) and/or --status VALUE");
  std::optional<F::Report> fault, status;
  with_fault_errors_mapped([&] {
    std::optional<std::uint16_t> mask;
    if (!o.mask.empty()) mask = F::parse_register_value(o.mask, "FAULTMASK");
    // A number, or the bits that are set by name or LinuxCNC pin (fault.no-enable, ...).
    if (!o.fault.empty()) fault = F::fault_report(F::parse_register_spec(o.fault, F::Register::Fault), mask);
    if (!o.status.empty()) status = F::status_report(F::parse_register_spec(o.status, F::Register::Status));
  });
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("source", "offline");
    j.set("fault", fault ? report_json(*fault) : app::Json());
    j.set("status", status ? report_json(*status) : app::Json());
    ctx.print_json(j);
    return;
  }
  if (fault) print_fault_report(std::cout, *fault);
  if (fault && status) std::cout << "\n";
  if (status) print_status_report(std::cout, *status);
}

// ------------------------------------------------------------------ faults mask
struct MaskOptions {
  std::string key;
  std::string state;
  ops::WriteOptions write;
};

void print_mask_state(std::uint16_t faultmask, std::uint16_t fault, const std::string& flags) {
  const auto& table = F::FaultTable::builtin();
  std::cout << "FAULTMASK " << lbp::hex_value(faultmask, 4) << ": ";
  const auto masked_bits = static_cast<std::uint16_t>(~faultmask & table.maskable_bits());
  if (masked_bits == 0) std::cout << "nothing masked";
  for (const auto& b : table.bits(F::Register::Fault))
    if (masked_bits & b.mask()) std::cout << b.name << " (bit " << b.bit << ", " << b.slug << ") masked";
  std::cout << "\n";
  for (const auto& b : table.bits(F::Register::Fault))
    if (b.maskable)
      std::cout << "  maskable: " << b.slug << " (" << b.name << ", bit " << b.bit << "): `i20 " << flags
                << " faults mask " << b.slug << " on|off`\n";
  std::cout << fault_output_text(F::fault_report(fault, faultmask)) << "\n";
}

void run_mask_show(Context& ctx) {
  const Readings r = ops::read_fault_registers(ctx.amp());
  if (!r.faultmask)
    throw ops::SafetyError("FAULTMASK cannot be read as a fact on " + ctx.amp().describe() + ": " +
                           ctx.amp().unconfirmed_reason(ctx.amp().db().get("FAULTMASK")));
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("faultmask", *r.faultmask).set("hex", lbp::hex_value(*r.faultmask, 4));
    j.set("maskable_bits", lbp::hex_value(F::FaultTable::builtin().maskable_bits(), 4));
    j.set("fault", report_json(F::fault_report(r.fault, r.faultmask)));
    ctx.print_json(j);
    return;
  }
  print_mask_state(*r.faultmask, r.fault, ctx.target_flags());
}

void print_mask_result(const F::BitInfo& bit, bool masked, const ops::MaskResult& m, const Readings& after,
                       const std::string& flags) {
  const bool written = m.run.outcome == ops::Outcome::Done;
  if (m.run.outcome == ops::Outcome::NothingToDo)
    std::cout << bit.name << " (bit " << bit.bit << ") is already " << (masked ? "masked" : "unmasked")
              << "; nothing written\n";
  else if (written)
    std::cout << "FAULTMASK " << lbp::hex_value(m.before, 4) << " -> " << lbp::hex_value(m.wanted, 4) << ": "
              << bit.name << " (bit " << bit.bit << ") " << (masked ? "masked" : "unmasked")
              << ", verified\n";
  std::cout << fault_output_text(F::fault_report(after.fault, after.faultmask)) << "\n";
  if (masked)
    std::cout << "A " << bit.slug
              << " fault no longer switches the fault output off. Unmask it before running "
              << "the machine: `i20 " << flags << " faults mask " << bit.slug << " off`\n"
              << "FAULTMASK is a working (RAM) register with no NV twin: set it again after a reset or power "
                 "cycle\n";
}

void run_mask_set(Context& ctx, const MaskOptions& o) {
  const F::BitInfo* bit = nullptr;
  with_fault_errors_mapped([&] { bit = &F::maskable_fault(o.key); });
  const bool masked = o.state == "on";
  // Refused before the link opens: what the rules already know (address, range).
  const ops::FaultMaskChange change(ctx.session().db(), o.key, masked, o.write);
  auto& amp = ctx.amp();
  ops::MaskResult m;
  with_fault_errors_mapped([&] { m = change.run_on(amp); });
  ctx.record(m.run.outcome);
  if (!m.run.ok()) {
    app::render::print_run(std::cout, m.run, amp.db(), "command line");
    std::cerr << "i20: " << app::render::error_line(m.run) << "\n";
    return;
  }
  const Readings& after = *m.after;
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("bit", bit->bit).set("name", bit->name).set("slug", bit->slug).set("masked", masked);
    j.set("faultmask_before", m.before)
        .set("faultmask_after", after.faultmask ? app::Json(*after.faultmask) : app::Json());
    j.set("written", m.run.outcome == ops::Outcome::Done).set("outcome", ops::to_string(m.run.outcome));
    j.set("fault", report_json(F::fault_report(after.fault, after.faultmask)));
    ctx.print_json(j);
    return;
  }
  print_mask_result(*bit, masked, m, after, ctx.target_flags());
}

void run_mask(Context& ctx, const MaskOptions& o) {
  if (o.key.empty() && o.state.empty()) return run_mask_show(ctx);
  if (o.state.empty())
    throw UsageError("say on or off: `i20 faults mask " + o.key + " on` masks it, `... off` unmasks it");
  run_mask_set(ctx, o);
}

// ------------------------------------------------------------------ clear-faults
struct ClearOptions {
  ops::WriteOptions write;
  unsigned wait_ms = static_cast<unsigned>(ops::timing::kClearFaultWait.count());
};

void print_remaining(const F::Report& remaining, const Readings& r, const std::string& flags) {
  for (const auto& line : remaining.lines) {
    std::cout << "\nRemains: " << bit_label(line) << (line.masked ? " [masked]" : "") << ": " << line.meaning
              << "\n  why:   " << why_remaining(line, r, flags) << "\n";
    for (std::size_t i = 0; i < line.checks.size(); ++i)
      std::cout << (i ? "         " : "  check: ") << i + 1 << ". " << line.checks[i] << "\n";
  }
  std::cout << "\nFix the causes, then run `i20 " << flags << " clear-faults` again.\n";
}

std::string names_of(const F::Report& report) {
  std::string out;
  for (const auto& line : report.lines) out += (out.empty() ? "" : ", ") + bit_label(line);
  return out.empty() ? "none" : out;
}

app::Json clear_json(const ops::ClearResult& res, const F::Report& cleared, const F::Report& remaining,
                     const Readings& r, const std::string& flags) {
  auto j = app::Json::object();
  j.set("cleared", r.fault == 0)
      .set("fault_before", res.fault_before)
      .set("fault_before_hex", lbp::hex_value(res.fault_before, 4));
  j.set("fault_after", r.fault)
      .set("fault_after_hex", lbp::hex_value(r.fault, 4))
      .set("status_after", r.status);
  j.set("took_ms", static_cast<long long>(res.took.count()));
  auto gone = app::Json::array();
  for (const auto& line : cleared.lines) gone.push(line_json(line, cleared));
  j.set("cleared_bits", std::move(gone));
  auto rem = app::Json::array();
  for (const auto& line : remaining.lines) {
    auto bit = line_json(line, remaining, &r);
    bit.set("why", why_remaining(line, r, flags));
    rem.push(std::move(bit));
  }
  j.set("remaining", std::move(rem)).set("readings", readings_json(r));
  return j;
}

void run_clear(Context& ctx, const ClearOptions& o) {
  const ops::FaultClear clear(ctx.session().db(), o.write, std::chrono::milliseconds(o.wait_ms));
  const auto res = clear.run_on(ctx.amp());
  const Readings& r = res.after;
  const auto cleared = res.cleared();
  const auto remaining = res.remaining();
  ctx.record(res.outcome());
  if (ctx.options.json) return ctx.print_json(clear_json(res, cleared, remaining, r, ctx.target_flags()));
  const std::string took = "CLEARFAULT acknowledged in " + std::to_string(res.took.count()) + " ms";
  if (res.fault_before == 0 && r.fault == 0) {
    std::cout << "No faults to clear: FAULT 0x0000 (" << took << ")\n"
              << fault_output_text(remaining) << "\n";
    return;
  }
  std::cout << took << ": FAULT " << lbp::hex_value(res.fault_before, 4) << " -> "
            << lbp::hex_value(r.fault, 4) << ", " << cleared.lines.size() << " cleared, "
            << remaining.lines.size() << " remaining\n";
  if (!cleared.lines.empty()) std::cout << "Cleared: " << names_of(cleared) << "\n";
  std::cout << fault_output_text(remaining) << "\n";
  if (r.fault == 0) return;
  print_remaining(remaining, r, ctx.target_flags());
  std::cerr << "i20: " << remaining.lines.size()
            << (remaining.lines.size() == 1 ? " fault remains" : " faults remain")
            << " after CLEARFAULT: " << names_of(remaining) << "\n";
}

// ------------------------------------------------------------------ registration
void add_allow_unverified(CLI::App* cmd, ops::WriteOptions& write) {
  cmd->add_flag("--allow-unverified", write.allow_unverified,
                "Write working (RAM) addresses the database does not confirm for this firmware");
}

void register_faults(CLI::App& app, Context& ctx) {
  auto* faults = app.add_subcommand(
      "faults",
      "Read FAULT, STATUS and FAULTMASK and explain every set bit: meaning, likely causes, what to check, "
      "and whether the cause is still there");
  faults->require_subcommand(0, 1);
  faults->footer(
      "Exit 0 whenever the registers were read, faults or not; scripts read --json. Examples:\n"
      "  i20 --port /dev/ttyUSB0 faults        i20 faults decode 0x0102 --status 0x0148\n"
      "  i20 --port /dev/ttyUSB0 faults mask bus-under-voltage on");

  auto decode_options = std::make_shared<DecodeOptions>();
  auto* decode = faults->add_subcommand(
      "decode", "Explain a FAULT value read elsewhere (HAL pin, log line, RPD FAULT H); needs no card");
  decode
      ->add_option("VALUE", decode_options->fault,
                   "FAULT value: 0x0102, 0102h, 0b100000010 or 258, or the set bits by name or LinuxCNC pin: "
                   "fault.no-enable,fault.bus-underv")
      ->type_name("VALUE");
  decode
      ->add_option("--status", decode_options->status,
                   "Also explain a STATUS value (a number, or bits: status.pid-on)")
      ->type_name("VALUE");
  decode->add_option("--mask", decode_options->mask, "FAULTMASK value, to say which faults are masked")
      ->type_name("VALUE");
  decode->callback([&ctx, decode_options] { run_decode(ctx, *decode_options); });

  auto mask_options = std::make_shared<MaskOptions>();
  auto* mask = faults->add_subcommand(
      "mask",
      "Show FAULTMASK, or mask/unmask a maskable fault (only bus-under-voltage) from the fault output");
  mask->add_option("BIT", mask_options->key,
                   "Fault to (un)mask: bus-under-voltage, BUSLOVFAULT, fault.bus-underv (LinuxCNC pin) or 8");
  mask->add_option("STATE", mask_options->state, "on = mask it, off = unmask it")
      ->check(CLI::IsMember({"on", "off"}));
  add_allow_unverified(mask, mask_options->write);
  mask->callback([&ctx, mask_options] { run_mask(ctx, *mask_options); });

  auto passive = std::make_shared<bool>(false);
  faults->add_flag("--passive", *passive,
                   passive_flag_help("FAULT and STATUS of every 8I20 of the card, explained,"));
  faults->callback([&ctx, faults, passive] {
    if (!faults->get_subcommands().empty()) return;
    if (*passive)
      run_passive_faults(ctx);
    else
      run_faults(ctx);
  });
}

void register_clear(CLI::App& app, Context& ctx) {
  auto options = std::make_shared<ClearOptions>();
  auto* clear = app.add_subcommand(
      "clear-faults",
      "Set CLEARFAULT, wait until the card acts on it, and report which faults remain and why (exit 5 when "
      "any remain). In setup mode (W6 down) the 8I20 drives no motor");
  add_allow_unverified(clear, options->write);
  clear->add_option("--wait", options->wait_ms, "How long CLEARFAULT may stay set, ms")
      ->check(CLI::Range(10, 60000))
      ->capture_default_str();
  clear->callback([&ctx, options] { run_clear(ctx, *options); });
}

}  // namespace

void register_fault_commands(CLI::App& app, Context& ctx) {
  register_faults(app, ctx);
  register_clear(app, ctx);
  register_watch_command(app, ctx);
}

}  // namespace i20::cli
