// i20 info | get | set | dump | reset | ports
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "context.hpp"
#include "lbp/bytes.hpp"
#include "lbp/local.hpp"
#include "link/ports.hpp"
#include "params/value.hpp"

namespace i20::cli {
namespace {

using params::Param;

std::string lbp_status_text(lbp::Byte status) {
  namespace L = lbp::local;
  if (status == 0) return "no errors";
  std::string text;
  const std::pair<lbp::Byte, const char*> bits[] = {{L::kStatusCrcError, "CRC error"},
                                                    {L::kStatusWatchdog, "watchdog timeout"},
                                                    {L::kStatusBufferOverflow, "buffer overflow"},
                                                    {L::kStatusInvalidWrite, "invalid write"},
                                                    {L::kStatusCommandTimeout, "command timeout"}};
  for (const auto& [bit, name] : bits)
    if (status & bit) text += (text.empty() ? "" : ", ") + std::string(name);
  return text;
}

std::string unconfirmed_note(const device::Value& v) {
  return v.address_confirmed ? "" : "address unconfirmed for this firmware";
}

app::Json value_json(const device::Value& v) {
  const auto& p = *v.param;
  auto j = app::Json::object();
  j.set("name", p.name).set("raw", v.raw);
  if (p.unit.empty())
    j.set("value", v.raw);
  else
    j.set("value", static_cast<double>(v.raw) * p.scale);
  j.set("unit", p.unit).set("text", params::format_engineering(p, v.raw));
  j.set("space", params::to_string(p.space)).set("address", p.address ? app::Json(*p.address) : app::Json());
  j.set("address_confirmed", v.address_confirmed)
      .set("twin", p.twin.empty() ? app::Json() : app::Json(p.twin));
  return j;
}

// ------------------------------------------------------------------ info
void run_info(Context& ctx) {
  auto& amp = ctx.session().amp();
  const auto info = amp.info();
  const auto& db = ctx.session().db();
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("target", ctx.session().link().describe()).set("card_name", info.card_name);
    j.set("unit_number", *info.unit_number).set("swrevision", *info.swrevision);
    j.set("working_map_confirmed", info.working_map_confirmed).set("lbp_version", info.lbp_version);
    j.set("unit_id", info.unit_id).set("unit_address", info.unit_address).set("lbp_status", info.lbp_status);
    j.set("lbp_status_text", lbp_status_text(info.lbp_status)).set("crc_errors", info.crc_errors);
    j.set("rpc_pitch", info.rpc_pitch).set("rpc_size", info.rpc_size);
    ctx.print_json(j);
    return;
  }
  const bool is_sim = db.simulator_swrevision() == info.swrevision;
  std::cout
      << info.card_name << " on " << ctx.session().link().describe() << "\n"
      << "  unit number    " << *info.unit_number << " (" << lbp::hex_value(*info.unit_number, 8) << ")\n"
      << "  firmware       SWREVISION " << lbp::hex_value(*info.swrevision, 4) << " (" << *info.swrevision
      << ")" << (is_sim ? ", the i20sim simulator" : "") << "\n"
      << "  working map    "
      << (info.working_map_confirmed
              ? "confirmed for this firmware: working parameters can be written"
              : "NOT confirmed for this firmware: NV parameters work; run `i20 discover` for working ones")
      << "\n"
      << "  LBP version    " << int(info.lbp_version) << "\n"
      << "  unit ID        " << int(info.unit_id) << "\n"
      << "  LBP status     " << lbp::hex_value(info.lbp_status, 2) << " (" << lbp_status_text(info.lbp_status)
      << ")\n"
      << "  CRC errors     " << int(info.crc_errors) << "\n"
      << "  RPC table      " << info.rpc_size << " bytes, pitch " << int(info.rpc_pitch) << "\n";
}

// ------------------------------------------------------------------ get
struct GetOptions {
  std::vector<std::string> names;
  bool raw = false;
  bool hex = false;
};

void run_get(Context& ctx, const GetOptions& o) {
  auto& db = ctx.session().db();
  std::vector<const Param*> list;
  for (const auto& n : o.names) list.push_back(&db.get(n));  // unknown names fail before the link opens
  const auto values = ctx.session().amp().read(list);
  if (ctx.options.json) {
    auto arr = app::Json::array();
    for (const auto& v : values) arr.push(value_json(v));
    ctx.print_json(arr);
    return;
  }
  for (const auto& v : values) {
    std::cout << v.param->name << " = ";
    if (o.hex)
      std::cout << lbp::hex_value(v.raw, static_cast<int>(v.param->width_bits / 4));
    else if (o.raw)
      std::cout << v.raw;
    else
      std::cout << params::format_engineering(*v.param, v.raw);
    if (!v.address_confirmed) std::cout << "  [" << unconfirmed_note(v) << "]";
    std::cout << "\n";
  }
}

// ------------------------------------------------------------------ set
struct SetOptions {
  std::vector<std::string> assignments;
  device::WriteOptions write;
};

void run_set(Context& ctx, const SetOptions& o) {
  auto& db = ctx.session().db();
  std::vector<device::Assignment> batch;
  for (const auto& a : o.assignments) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == a.size())
      throw UsageError("'" + a + "' is not NAME=VALUE (e.g. NVBRAKEONV=320V or NVMAXCURRENT=750)");
    const auto& p = db.get(a.substr(0, eq));
    batch.push_back({&p, params::parse_value(p, a.substr(eq + 1))});
    device::check_offline(p, batch.back().raw, o.write);  // before the link is even opened
  }
  auto& amp = ctx.session().amp();
  for (const auto& b : batch) amp.check_write(*b.param, b.raw, o.write);  // all before the first write
  const auto reports = amp.write(batch, o.write);
  bool reset_needed = false;
  auto arr = app::Json::array();
  for (const auto& r : reports) {
    reset_needed |= r.needs_reset;
    if (ctx.options.json) {
      auto j = app::Json::object();
      j.set("name", r.param->name).set("raw", r.raw).set("text", params::format_engineering(*r.param, r.raw));
      j.set("verified", r.verified).set("needs_reset", r.needs_reset);
      arr.push(std::move(j));
      continue;
    }
    std::cout << r.param->name << " = " << params::format_engineering(*r.param, r.raw) << " (" << r.raw << ")"
              << (r.needs_reset ? " written to EEPROM" : " written") << (r.verified ? ", verified" : "")
              << "\n";
  }
  if (ctx.options.json)
    ctx.print_json(arr);
  else if (reset_needed)
    std::cout << "NV values take effect after the 8I20 is reset: run `i20 reset`\n";
}

// ------------------------------------------------------------------ dump
void print_dump_table(const std::vector<device::Value>& values) {
  std::cout << std::left << std::setw(16) << "NAME" << std::setw(14) << "VALUE" << std::setw(12) << "RAW"
            << std::setw(16) << "NV TWIN"
            << "NOTE\n";
  for (const auto& v : values) {
    const auto& p = *v.param;
    const std::string twin = p.is_nv() ? "" : p.twin;
    std::cout << std::left << std::setw(16) << p.name << std::setw(14) << params::format_engineering(p, v.raw)
              << std::setw(12) << v.raw << std::setw(16) << (twin.empty() ? "-" : twin) << unconfirmed_note(v)
              << "\n";
  }
}

void print_dump_yaml(const std::vector<device::Value>& values) {
  std::cout << "# i20 dump\n";
  for (const auto& v : values) {
    const auto& p = *v.param;
    std::cout << "- {name: " << p.name << ", raw: " << v.raw << ", value: \""
              << params::format_engineering(p, v.raw) << "\", space: " << params::to_string(p.space)
              << ", address_confirmed: " << (v.address_confirmed ? "true" : "false") << "}\n";
  }
}

void run_dump(Context& ctx, const std::string& format) {
  auto& db = ctx.session().db();
  std::vector<const Param*> list;
  for (const auto& p : db.all())
    if (p.address) list.push_back(&p);
  const auto values = ctx.session().amp().read(list);
  const std::string f = ctx.options.json ? "json" : format;
  if (f == "json") {
    auto arr = app::Json::array();
    for (const auto& v : values) arr.push(value_json(v));
    ctx.print_json(arr);
  } else if (f == "yaml") {
    print_dump_yaml(values);
  } else {
    print_dump_table(values);
  }
}

// ------------------------------------------------------------------ reset
void run_reset(Context& ctx, bool yes) {
  auto& session = ctx.session();
  const std::string where = session.link().describe();
  if (!yes && !ctx.confirm("Reset the 8I20 on " + where + "? NV values become the working values")) {
    std::cerr << "i20: reset not confirmed; nothing was sent (pass --yes in scripts)\n";
    ctx.exit_code = app::kBadInput;
    return;
  }
  session.amp().reset();
  if (ctx.options.json)
    ctx.print_json(app::Json::object().set("reset", true).set("target", where));
  else
    std::cout << "8I20 on " << where << " reset; it answers again and runs from its NV values\n";
}

// ------------------------------------------------------------------ ports
void run_ports(Context& ctx) {
  const auto ports = link::list_ports();
  if (ctx.options.json) {
    auto arr = app::Json::array();
    for (const auto& p : ports) {
      auto j = app::Json::object();
      j.set("device", p.device.string()).set("by_id", p.by_id.string()).set("driver", p.driver);
      j.set("vendor_id", p.vendor_id ? app::Json(*p.vendor_id) : app::Json());
      j.set("product_id", p.product_id ? app::Json(*p.product_id) : app::Json());
      j.set("manufacturer", p.manufacturer).set("product", p.product).set("serial", p.serial_number);
      arr.push(std::move(j));
    }
    ctx.print_json(arr);
    return;
  }
  if (ports.empty()) {
    std::cout << "no serial ports found; plug in the 3I22 (USB) and check `dmesg` for a new ttyUSB device\n";
    return;
  }
  for (const auto& p : ports) std::cout << p.summary() << "\n";
}

}  // namespace

void register_param_commands(CLI::App& app, Context& ctx) {
  auto* info = app.add_subcommand("info", "Card name, unit number, firmware, LBP status and CRC error count");
  info->callback([&ctx] { run_info(ctx); });

  auto get_options = std::make_shared<GetOptions>();
  auto* get = app.add_subcommand(
      "get", "Read parameters by name, in engineering units (e.g. i20 get NVBRAKEONV BUSV)");
  get->add_option("NAME", get_options->names, "Parameter names")->required();
  auto* raw = get->add_flag("--raw", get_options->raw, "Raw integers as on the wire");
  get->add_flag("--hex", get_options->hex, "Raw values in hexadecimal")->excludes(raw);
  get->callback([&ctx, get_options] { run_get(ctx, *get_options); });

  auto set_options = std::make_shared<SetOptions>();
  auto* set = app.add_subcommand(
      "set",
      "Write parameters: NAME=VALUE with units (NVBRAKEONV=320V, NVMAXCURRENT=7.5A) or raw integers "
      "(NVMAXCURRENT=750). Every value is checked before the first write; NV writes are verified and take "
      "effect "
      "after a reset");
  set->add_option("ASSIGNMENT", set_options->assignments, "NAME=VALUE pairs")->required();
  set->add_flag("--allow-unverified", set_options->write.allow_unverified,
                "Write working (RAM) addresses the database does not confirm for this firmware");
  set->add_flag("--force", set_options->write.force, "Write guarded parameters (NVBAUDRATE, setpoints)");
  set->callback([&ctx, set_options] { run_set(ctx, *set_options); });

  auto format = std::make_shared<std::string>("table");
  auto* dump = app.add_subcommand("dump", "Read every parameter in one pipelined pass");
  dump->add_option("--format", *format, "table, json or yaml")
      ->check(CLI::IsMember({"table", "json", "yaml"}));
  dump->callback([&ctx, format] { run_dump(ctx, *format); });

  auto yes = std::make_shared<bool>(false);
  auto* reset = app.add_subcommand("reset", "Reset the 8I20 so NV values become live (asks first)");
  reset->add_flag("--yes,-y", *yes, "Do not ask");
  reset->callback([&ctx, yes] { run_reset(ctx, *yes); });

  auto* ports = app.add_subcommand("ports", "List serial ports (USB adapters with vendor, product, serial)");
  ports->callback([&ctx] { run_ports(ctx); });
}

}  // namespace i20::cli
