// SPDX-License-Identifier: GPL-2.0-or-later
// Writes the seed corpora in fuzz/corpus/ from real traffic and the toolkit's own
// encoders, so the fuzzers start from inputs the code accepts: the bytes `i20 dump` and
// an NV write put on the line (recorded against the virtual 8I20), the UDP packets of
// discovery and an SSLBP passthrough session (recorded against the virtual 7I96S), the
// HostMot2 tables of both virtual cards, the shipped YAML files, and typed values.
//
//   build-fuzz/fuzz/fuzz_make_seeds SOURCE_DIR       (rewrites SOURCE_DIR/fuzz/corpus/*)
//
// Not a fuzz target and not run by CI: the output is checked in.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "device/amp.hpp"
#include "eth/anything_io.hpp"
#include "eth/passthrough_link.hpp"
#include "ethsim/virtual_8i20_remote.hpp"
#include "ethsim/virtual_board.hpp"
#include "lbp/command.hpp"
#include "lbp16/lbp16.hpp"
#include "link/pipelined_link.hpp"
#include "ops/core/timing.hpp"
#include "params/param_db.hpp"
#include "sim/rpc_table.hpp"
#include "sim/sim_stream.hpp"

namespace {

using namespace i20;
namespace fs = std::filesystem;

fs::path g_out;

void write_seed(const std::string& target, const std::string& name, const lbp::Bytes& bytes) {
  const fs::path dir = g_out / target;
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

void write_seed(const std::string& target, const std::string& name, const std::string& text) {
  write_seed(target, name, lbp::Bytes(text.begin(), text.end()));
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

lbp::Bytes cat(std::initializer_list<lbp::Bytes> parts) {
  lbp::Bytes out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// ---- setup-mode traffic, recorded ---------------------------------------------------------

// Passes bytes to the in-process simulator and keeps what the host wrote and read.
class RecordingStream final : public link::ByteStream {
 public:
  RecordingStream(std::unique_ptr<link::ByteStream> inner, lbp::Bytes& sent, lbp::Bytes& received)
      : inner_(std::move(inner)), sent_(sent), received_(received) {}
  void write(lbp::ByteView bytes) override {
    sent_.insert(sent_.end(), bytes.begin(), bytes.end());
    inner_->write(bytes);
  }
  std::size_t read_some(std::span<lbp::Byte> buffer, link::Clock::time_point deadline) override {
    const std::size_t n = inner_->read_some(buffer, deadline);
    received_.insert(received_.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
    return n;
  }
  void discard_input() override { inner_->discard_input(); }
  unsigned baud() const override { return inner_->baud(); }
  std::string name() const override { return "recording"; }

 private:
  std::unique_ptr<link::ByteStream> inner_;
  lbp::Bytes& sent_;
  lbp::Bytes& received_;
};

struct Traffic {
  lbp::Bytes sent, received;
};

Traffic record_setup_session() {
  Traffic t;
  link::PipelinedLink link(std::make_unique<RecordingStream>(sim::make_sim_stream(), t.sent, t.received),
                           ops::timing::serial_link({}, {}));
  auto db = params::ParamDb::builtin();
  device::Amp8i20 amp(link, db, ops::timing::amp());
  (void)amp.info();
  std::vector<const params::Param*> all;
  for (const auto& p : db.all()) all.push_back(&p);
  (void)amp.read(all);
  (void)amp.write("NVBRAKEONV", 19000, {});
  (void)amp.read_rpc_table();
  return t;
}

// The splitter's input format: [table choice][chunk length - 1, chunk]...
lbp::Bytes chunked(std::uint8_t table_choice, const lbp::Bytes& stream, std::size_t chunk) {
  lbp::Bytes out{table_choice};
  for (std::size_t i = 0; i < stream.size(); i += chunk) {
    const std::size_t n = std::min(chunk, stream.size() - i);
    out.push_back(static_cast<lbp::Byte>(n - 1));
    out.insert(out.end(), stream.begin() + static_cast<std::ptrdiff_t>(i),
               stream.begin() + static_cast<std::ptrdiff_t>(i + n));
  }
  return out;
}

// The virtual 8I20 target's format: [flags][seed][event: gap << 5 | (length - 1), bytes]...
lbp::Bytes events(std::uint8_t flags, const lbp::Bytes& stream, std::uint8_t gap) {
  lbp::Bytes out{flags, 7};
  for (std::size_t i = 0; i < stream.size(); i += 32) {
    const std::size_t n = std::min<std::size_t>(32, stream.size() - i);
    out.push_back(static_cast<lbp::Byte>(gap << 5 | (n - 1)));
    out.insert(out.end(), stream.begin() + static_cast<std::ptrdiff_t>(i),
               stream.begin() + static_cast<std::ptrdiff_t>(i + n));
  }
  return out;
}

void lbp_seeds() {
  const Traffic setup = record_setup_session();
  write_seed("lbp_command_splitter", "dump-and-nv-write", chunked(0, setup.sent, 7));
  const auto table = sim::preloaded_rpc_table(sim::RegisterMap::builtin());
  const auto rpc3 = lbp::frame(lbp::rpc(3, lbp::Bytes{0, 0, 0, 0}, 8));
  write_seed("lbp_command_splitter", "fuzzed-table-rpc3", cat({{1}, table, {4}, rpc3}));

  // Reply splitter: the sizes of a read batch, then the card's replies to it.
  const std::vector<lbp::Command> batch{
      lbp::local_read(lbp::local::kGetStatus), lbp::read(2164, lbp::DataSize::Two),
      lbp::read(0, lbp::DataSize::Four), lbp::write(0x0100, lbp::DataSize::Two, 5)};
  auto stream = sim::make_sim_stream();
  stream->write(lbp::frame_all(batch));
  lbp::Bytes replies(64);
  replies.resize(stream->read_some(replies, link::Clock::now() + std::chrono::milliseconds(200)));
  lbp::Bytes seed{static_cast<lbp::Byte>(batch.size())};
  for (const auto& c : batch) seed.push_back(static_cast<lbp::Byte>(c.reply_bytes));
  seed.push_back(static_cast<lbp::Byte>(replies.size() - 1));
  seed.insert(seed.end(), replies.begin(), replies.end());
  write_seed("lbp_reply_splitter", "status-swrevision-read-write", seed);

  write_seed("sim_8i20", "setup-dump-and-nv-write", events(0x00, setup.sent, 0));
  write_seed("sim_8i20", "setup-slow-bytes", events(0x00, lbp::frame_all(batch), 2));
  // Operate mode: the SSLBP cycle (RPC 3), one packet per cycle, 10 ms apart.
  lbp::Bytes cycles;
  for (int i = 0; i < 4; ++i) {
    const auto cycle = lbp::frame(lbp::rpc(3, lbp::Bytes{0, 0, 0, 0}, 8));
    cycles.push_back(static_cast<lbp::Byte>(5 << 5 | (cycle.size() - 1)));
    cycles.insert(cycles.end(), cycle.begin(), cycle.end());
  }
  write_seed("sim_8i20", "operate-rpc3-cycles", cat({{0x01, 3}, cycles}));
}

// ---- Ethernet traffic, recorded -----------------------------------------------------------

// An in-process "UDP" to a virtual card that keeps every request payload.
class RecordingBus final : public eth::Lbp16Transport {
 public:
  RecordingBus(ethsim::VirtualBoard& board, std::vector<lbp::Bytes>& packets)
      : card_(board), packets_(packets) {}
  std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands, eth::Resend) override {
    const lbp::Bytes request = lbp::lbp16::encode_packet(commands);
    packets_.push_back(request);
    const auto reply = card_.handle(request, ethsim::Clock::now());
    return lbp::lbp16::split_reply(commands, reply.value_or(lbp::Bytes{}));
  }
  std::string describe() const override { return "recording"; }
  eth::TransportStats stats() const override { return {}; }

 private:
  ethsim::VirtualBoard& card_;
  std::vector<lbp::Bytes>& packets_;
};

ethsim::VirtualBoardOptions card_options(ethsim::BoardKind kind) {
  ethsim::VirtualBoardOptions o;
  o.config = ethsim::BoardConfig::preset(kind);
  o.remotes = [](unsigned, unsigned) {
    return std::make_unique<ethsim::Virtual8i20Remote>(ethsim::Virtual8i20Remote::default_options(),
                                                       ethsim::Clock::now());
  };
  return o;
}

// The ethsim target's format: [card][mode][gap, length (2 bytes), payload]...
lbp::Bytes packets_seed(std::uint8_t card, const std::vector<lbp::Bytes>& packets) {
  lbp::Bytes out{card, 0};
  for (const auto& p : packets) {
    out.push_back(1);
    lbp::append_le(out, p.size(), 2);
    out.insert(out.end(), p.begin(), p.end());
  }
  return out;
}

void eth_seeds() {
  for (const auto kind : {ethsim::BoardKind::I7i96s, ethsim::BoardKind::I7i92t}) {
    const std::string name(ethsim::board_kind_name(kind));
    ethsim::VirtualBoard board(card_options(kind), ethsim::Clock::now());
    std::vector<lbp::Bytes> packets;
    {
      RecordingBus bus(board, packets);
      (void)eth::identify(bus);
      (void)eth::read_hostmot2(bus);
    }
    // Discovery reads, in order: the replies are what the hostmot2 target feeds back.
    lbp::Bytes tables;
    for (std::size_t i = 1; i < packets.size(); ++i) {
      const auto parsed = lbp::lbp16::parse_request(packets[i]);
      const auto reply = board.handle(packets[i], ethsim::Clock::now());
      if (reply) tables.insert(tables.end(), reply->begin(), reply->end());
      (void)parsed;
    }
    write_seed("hostmot2", name + "-discovery", tables);
    for (std::size_t i = 0; i < packets.size(); ++i)
      write_seed("lbp16_packet", name + "-discovery-" + std::to_string(i), packets[i]);

    // A passthrough session: open the channel, read and write a parameter.
    auto bus = std::make_unique<RecordingBus>(board, packets);
    // The passthrough as the programs open it, so the seeds are their traffic.
    eth::SslbpPassthroughLink link(std::move(bus), eth::EthTarget{}, ops::timing::passthrough({}, {}));
    auto db = params::ParamDb::builtin();
    device::Amp8i20 amp(link, db, ops::timing::amp());
    (void)amp.info();
    (void)amp.read("NVMAXCURRENT");
    (void)amp.write("NVBRAKEONV", 19000, {});
    write_seed("ethsim_card", name + "-discovery-and-passthrough",
               packets_seed(kind == ethsim::BoardKind::I7i92t ? 1 : 0, packets));
    write_seed("lbp16_packet", name + "-passthrough-last", packets.back());
  }
}

// ---- text inputs --------------------------------------------------------------------------

std::size_t param_index(const params::ParamDb& db, const std::string& name) {
  const auto& all = db.all();
  for (std::size_t i = 0; i < all.size(); ++i)
    if (all[i].name == name) return i;
  throw std::runtime_error("no parameter " + name);
}

void text_seeds(const fs::path& source) {
  const auto db = params::ParamDb::builtin();
  write_seed("param_db", "shipped-database",
             std::string("\x00\x20\xE1", 3) + read_text(source / "params/8i20.yaml"));
  write_seed("param_db", "overlay-for-revision",
             std::string("\x01\x21\xE1", 3) +
                 "schema: 1\nswrevision: 0xE121\nparameters:\n"
                 "  - name: BRAKEONV\n    address: 0x0120\n"
                 "    provenance: {source: i20 discover, confirmed_on: [0xE121]}\n");
  write_seed("param_db", "two-overlays",
             std::string("\x02\x20\xE1", 3) + "parameters:\n  - name: NVMAXCURRENT\n    max: 2000\n" +
                 std::string(1, '\0') +
                 "parameters:\n  - name: MYREG\n    space: ram\n    address: 0x0300\n    width: 16\n"
                 "    signed: true\n    access: rw\n    description: a new register\n"
                 "    provenance: {source: test, confirmed_on: []}\n");
  for (const auto& entry : fs::directory_iterator(source / "profiles"))
    if (entry.path().extension() == ".yaml")
      write_seed("profile_loader", entry.path().stem().string(), read_text(entry.path()));
  write_seed("fault_table", "shipped-faults", read_text(source / "params/faults.yaml"));

  const auto value = [&](const std::string& name, std::uint8_t kind, const std::string& text) {
    lbp::Bytes b{static_cast<lbp::Byte>(param_index(db, name)), kind};
    b.insert(b.end(), text.begin(), text.end());
    return b;
  };
  write_seed("value_parse", "volts", value("NVBRAKEONV", 3, "190.5 V"));
  write_seed("value_parse", "milliamps", value("NVMAXCURRENT", 0, "750mA"));
  write_seed("value_parse", "hex", value("FAULTMASK", 1, "0xFEFF"));
  write_seed("value_parse", "h-suffix", value("FAULTMASK", 1, "FEFFh"));
  write_seed("value_parse", "degrees", value("ANGLE", 2, "180deg"));
  write_seed("value_parse", "negative", value("QSETPOINT", 2, "-100"));
  write_seed("value_parse", "exponent", value("NVBRAKEONV", 3, "1.9e2V"));
  write_seed("value_parse", "ohms", value("NVKQP", 1, "1.9 ohm"));
  write_seed("value_parse", "millihenry", value("NVKQP", 2, "6.2 mH"));

  write_seed("fault_register_value", "hex", std::string("0x0102"));
  write_seed("fault_register_value", "h-suffix", std::string("0102h"));
  write_seed("fault_register_value", "binary", std::string("0b1_0000_0010"));
  write_seed("fault_register_value", "decimal", std::string("258"));

  write_seed("sim_control", "world",
             std::string("busv 320\ntemp 45\nenable off\nnoise busv 0.5\nseed 9\nfault overcurrent on\n"
                         "fault 11 off\nshow\nget FAULT\n"));
  write_seed("sim_control", "injection",
             std::string("corrupt 0.01\ndrop 0.05\ndelay 3\nreset-after 10\nclearfault-stuck on\n"
                         "eeprom-power-loss torn\nmute-after 4\nmute-after off\npower cycle\n"
                         "set maxcurrent 1234\nhelp\n"));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: fuzz_make_seeds SOURCE_DIR\n";
    return 2;
  }
  const fs::path source = argv[1];
  g_out = source / "fuzz" / "corpus";
  lbp_seeds();
  eth_seeds();
  text_seeds(source);
  std::cout << "seeds written to " << g_out << "\n";
  return 0;
}
