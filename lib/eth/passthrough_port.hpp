// SPDX-License-Identifier: GPL-2.0-or-later
// One SSERIAL port of an Ethernet card held in SSLBP setup mode, so that the 8I20s on its
// channels can be read and written through the passthrough (8I20 manual, "SETUP START",
// "SETUP MODE OPERATION"). SslbpPassthroughLink is one channel of it; a fleet uses
// link(channel) for each channel of the same port, so that one DOIT serves them all.
//
// Opening: identify the card (space 7), read the HostMot2 IDROM, locate the port, check
// that no other host is running the card (running_host.hpp: refused with
// RunningHostError unless options.running_host.take_over), stop the port, read SSLBP's
// parameters and the remote baud rates, setup-start the channels of the mask, check that
// an 8I20 answered on each (INTERFACE1 = "8I20"). Each 8I20's NV access and RPC memory
// modes are learnt from the first reads of them (0xCC, 0xCA) the device layer sends, which
// run in whatever mode the card is in; until then they count as unknown. A setup start
// does none of the device specific setup of a normal start (manual): no fault is cleared,
// no current loop enabled. The port is stopped when the
// object goes away.
//
// Batching. Each LBP command is one passthrough step: CS (and INTERFACE0 for a write)
// then a DOIT. A DOIT with several channel bits runs the step of every channel at once
// (a "round"). One UDP packet carries many rounds, each as
//
//     write INTERFACE0s (writes only), write CSs, write COMMAND = DOIT | mask,
//     WaituS (space 4) sized to the serial time at the remote's baud plus processing,
//     read COMMAND, DATA, INTERFACE0s (reads only)
//
// with the registers of neighbouring channels moved by one block access each. A round is
// done when its COMMAND read back 0; its DATA bits name channels whose transfer failed
// (their CS is then read and decoded). When COMMAND still reads busy (the WaituS was too
// short: a slow remote, an EEPROM write that took longer), SSLBP ignored the next DOITs
// of that packet, or, in a microsecond race, ran one of them: so the link polls until
// COMMAND clears and replays from the late round on, that round alone in its packet (its
// own poll then reads its result; batching resumes after it). The packing rules keep a
// replay exact:
//   - a step that must not run twice (0xFA, 0xFE) travels alone in its packet;
//   - a data write never follows a data read of the same channel in one packet (a replayed
//     read must not see a write that ran early);
//   - other local writes open a packet for their channel; 0xEC (NV access) may sit
//     anywhere when the channel's mode at the start of the packet is known (or set by its
//     first step in the packet, an 0xEC), because a replay first restores the mode the
//     late round expects (one DOIT of its own); an
//     0xEA that turns RPC memory access off may follow the 0xEA that turned it on, or
//     any step when the mode is known, because the replay's bracket turns it on again;
//   - an EEPROM write (a data write while NV access is on, or not known to be off) waits
//     inside the packet (WaituS up to 65535 us, options.nv_write_time per word); a cell
//     that takes longer is waited for and not written again: DATA, once COMMAND clears, is
//     its outcome, and the rest of the packet replays. (A replay caused by an earlier late
//     round can still write a cell twice, with the same value.)
// Late and repeated copies: the network may deliver a packet late or twice, and the copy
// runs again by itself. So no packet relies on, or leaves, an 8I20 in NV access or RPC
// memory mode: a channel whose commands in a packet run in such a mode gets it set by the
// packet's first DOITs and cleared by its last (bracket_modes); between packets every 8I20
// is in normal access, whatever mode the commands asked for. A copy then writes the EEPROM
// cell it was meant for, never working memory at the cell's EEPROM address, and leaves
// the modes off.
// Packets stay within 1472 bytes each way and options.max_packet_wait of WaituS. Cards
// without LBP16 space 4 (LBP16 version < 3) get one round per packet and polling.
//
// Assumption (the manual is silent): SSLBP takes CS and INTERFACE0 when it accepts a DOIT,
// so the next round's register writes cannot disturb a DOIT still in flight.
//
// Another host: every packet also reads RXUDPCount. When packets that are not ours reached
// the card since our last one (LinuxCNC started, or kept running after a take-over), the
// exchange fails with ForeignHostError and its results are discarded: that host's DOITs
// run whatever our CS and INTERFACE0 hold, and its DOIT could be taken for ours.
//
// Thread safety: execute() and the links may be used from several threads; links of
// different channels that execute at about the same time (within options.gather_window)
// are combined into one execute() (command_combiner.hpp). Ports of one card used at once
// share one transport (board_transport()).
//
// Where the code is: the port's lifecycle (opening, the running-host and foreign-packet
// checks, resync, closing) in passthrough_port.cpp; packing, mode brackets, running
// packets and replay in passthrough_packing.cpp, with the working state of an execute()
// in passthrough_work.hpp; combining the links' batches in command_combiner.cpp.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "eth/anything_io.hpp"
#include "eth/command_combiner.hpp"
#include "eth/fenced_transport.hpp"
#include "eth/passthrough_plan.hpp"
#include "eth/running_host.hpp"
#include "eth/sslbp_port.hpp"
#include "eth/target.hpp"
#include "eth/transport.hpp"
#include "eth/udp_client.hpp"
#include "link/link.hpp"

namespace i20::eth {

struct PassthroughOptions {
  UdpOptions udp;
  // Late requests (fenced_transport.hpp): how long an unanswered one may still arrive.
  FenceOptions fence;
  SslbpOptions sslbp;
  // How often a passthrough packet whose reply was lost is sent again, after the fence and
  // a read-only probe (PassthroughPort::lost_reply; a step that must not run twice never
  // is). ops sends 0 (ops::timing::passthrough): it repeats a lost exchange itself, within
  // its retry budget, and a write only after a read-back.
  link::Given<unsigned> lost_packet_resends;
  RunningHostCheck running_host;
  // Refuse a channel whose remote is not an 8I20 (INTERFACE1 after setup start).
  bool require_8i20 = true;
  // Added to the serial time estimate of every DOIT: SSLBP's own processing.
  std::chrono::microseconds overhead{60};
  // Character times the remote needs to see a command as complete: an 8I20 ends a
  // packet only after a quiet line (at most 25.5 character times; manual, "FRAMING").
  unsigned turnaround_characters = 26;
  // EEPROM write time per 16-bit word while NV access is on: a cell write takes
  // milliseconds (docs/facts.md section 7). Underestimating costs a poll.
  std::chrono::microseconds nv_write_time{5000};
  // DOITs per request packet; 0 = as many as fit. 1 is the unbatched behaviour: one LBP
  // command per round trip (the figures before batching).
  unsigned max_doits_per_packet = 0;
  // Total WaituS one packet may ask for; the card answers only after it.
  link::Given<std::chrono::milliseconds> max_packet_wait;
  // Longest extra wait the link adds to every DOIT after DOITs outlived their WaituS.
  link::Given<std::chrono::milliseconds> max_slack;
  // How long a link waits for the links of other channels to join its execute().
  link::Given<std::chrono::microseconds> gather_window;
  // Late DOITs tolerated in one execute() before the link gives up: each costs a replay,
  // and a remote that is always slower than its estimate is better reported than chased.
  link::Given<unsigned> max_replays;
  // How long closing the port may take to stop SSLBP (best effort: setup mode drives no
  // motor), whatever is left of the command's time.
  link::Given<std::chrono::milliseconds> close_budget;
  // Openings in all when one fails because the network lost or delayed a datagram
  // (link::TimeoutError, LatePacketError), within the bound in force. The opening writes only
  // SSLBP's own registers (its stop and setup start), which the next opening writes again over
  // the same transport, whose fence first waits out the failed one's packets. A reply of the
  // wrong shape, SSLBP's error, another host, a card that is not what the target needs and
  // the time being up are not retried: the first one is reported.
  link::Given<unsigned> opening_attempts;
};

// What answered on a channel at setup start.
struct RemoteInfo {
  std::string name{};             // "8I20"
  std::uint32_t unit_number = 0;  // INTERFACE0 after start
  std::uint32_t cs = 0;
};

struct PassthroughStats {
  std::uint64_t commands = 0;          // LBP commands completed (all channels)
  std::uint64_t round_trips = 0;       // UDP request packets, polls included
  std::uint64_t max_round_trips = 0;   // of any single execute()
  std::uint64_t doits = 0;             // DOITs (one serves every channel of its round)
  std::uint64_t late_doits = 0;        // DOITs still busy at their read-back
  std::uint64_t replays = 0;           // packets run again from a late DOIT on
  std::uint64_t restarts = 0;          // setup restarts after errors
  std::chrono::microseconds slack{0};  // extra wait per DOIT learnt from late ones
  // Estimated serial time of the DOITs at the remotes' baud (the slowest channel of each
  // round), what the WaituS were sized from, EEPROM time excluded.
  std::chrono::microseconds serial_time{0};
};

class PassthroughPort : public std::enable_shared_from_this<PassthroughPort> {
 public:
  // Opens UDP to `card` and sets the channels of `channel_mask` up, again after a link
  // failure (PassthroughOptions::opening_attempts). Throws RunningHostError, DiscoveryError
  // (not a HostMot2 card, no such port or channel, no 8I20) or link::LinkError.
  static std::shared_ptr<PassthroughPort> open(const HostPort& host_port, unsigned sserial_port,
                                               std::uint8_t channel_mask, PassthroughOptions options);
  // Several ports of one card at once (a fleet over a 7I92T's two ports): open them over
  // one board_transport(), or each one's check for another host sees the other's packets
  // (and refuses, or discards its results).
  static std::shared_ptr<PassthroughPort> open(std::shared_ptr<Lbp16Transport> card, unsigned sserial_port,
                                               std::uint8_t channel_mask, PassthroughOptions options);
  // A SharedTransport over UDP to `card`, for the open() above.
  static std::shared_ptr<Lbp16Transport> board_transport(const HostPort& host_port, const UdpOptions& options,
                                                         const FenceOptions& fence);
  // The same over any transport (tests inject faults here).
  PassthroughPort(std::shared_ptr<Lbp16Transport> bus, unsigned sserial_port, std::uint8_t channel_mask,
                  PassthroughOptions options);
  ~PassthroughPort();
  PassthroughPort(const PassthroughPort&) = delete;
  PassthroughPort& operator=(const PassthroughPort&) = delete;

  using Batch = ChannelBatch;
  // Executes each channel's batch, the channels side by side: the k-th commands of every
  // batch share one DOIT. At most one batch per channel. UsageError for a channel not in
  // the mask.
  std::vector<ChannelResult> execute(std::span<const Batch> batches);

  // A link::Link to one channel. Links of several channels used by several threads at
  // once are combined into shared DOITs.
  std::unique_ptr<link::Link> link(unsigned channel);

  std::uint8_t channel_mask() const { return mask_; }
  const RemoteInfo& remote(unsigned channel) const;
  const BoardIdentity& board() const { return board_; }
  const SserialPort& port() const { return sslbp_->port(); }
  const SslbpParameters& sslbp_parameters() const { return parameters_; }
  std::uint32_t baud(unsigned channel) const;  // SSLBP's rate towards the channel (0: unknown)
  const HostActivity& host_activity() const { return activity_; }  // seen before the stop
  PassthroughStats stats() const;
  TransportStats transport_stats() const;
  std::vector<std::string> notes() const { return notes_; }
  // "eth 192.168.1.121 port 0" / "eth 192.168.1.121 ch 3".
  std::string describe() const;
  std::string describe(unsigned channel) const;
  const PassthroughOptions& options() const { return options_; }

  // Serial time of one DOIT of `step` on `channel` at its baud, turnaround included.
  std::chrono::microseconds serial_time(const PassthroughStep& step, unsigned channel) const;
  // Estimated time of one DOIT of `step` on `channel` while NV access is `nv_mode`
  // (nullopt: not known), what the WaituS asks for: serial time, processing, what late
  // DOITs taught (stats().slack), and the EEPROM write time of an EEPROM write.
  std::chrono::microseconds settle_for(const PassthroughStep& step, unsigned channel,
                                       std::optional<std::uint8_t> nv_mode) const;

 private:
  struct Channel;
  struct Slot;
  struct Round;
  struct PacketResult;

  // ---- lifecycle (passthrough_port.cpp) ----
  void start_setup();
  void read_nv_modes();
  bool another_host_runs_the_port();
  void resync();
  void refuse_if_another_host_took_the_port();
  // `received`: RXUDPCount read in our latest packet; `sent`: our packets by then.
  void require_no_foreign_packets(std::uint16_t received, std::uint64_t sent);
  // ForeignHostError when the transport's ledger counted foreign arrivals since `before`.
  void require_undisturbed(std::uint64_t foreign_before);

  // ---- packing and replay (passthrough_packing.cpp) ----
  void run(std::vector<Channel>& channels);
  // The rounds of the next packet under the packing rules, at most `max_doits` (0: no limit).
  // `leave`: the packet will be bracketed with mode-clearing DOITs (see bracket_modes).
  std::vector<Round> next_packet(std::vector<Channel>& channels, unsigned max_doits, bool leave) const;
  bool rpc_off_may_follow(const PassthroughStep& step, const Channel& c, std::size_t first_in_packet) const;
  void lay_out(Round& round, const std::vector<Channel>& channels) const;
  void bracket_modes(std::vector<Round>& packet, const std::vector<Channel>& channels, bool leave) const;
  std::pair<std::vector<Round>, std::vector<Round>> mode_brackets(const std::vector<const Round*>& packet,
                                                                  const std::vector<Channel>& channels,
                                                                  bool leave) const;
  void learn_from_late(const Round& round);
  static bool is_eeprom_write(const Round& round);
  PacketResult run_packet(std::vector<Round>& packet, std::vector<Channel>& channels);
  PacketResult lost_reply(std::vector<Round>& packet, std::vector<Channel>& channels);
  std::vector<std::uint16_t> interface0_addresses(const Round& round,
                                                  const std::vector<Channel>& channels) const;
  void complete_by_polling(const Round& round, std::vector<Channel>& channels, const Completion& done);
  std::optional<Round> restore_round(const std::vector<Round>& packet, std::size_t late,
                                     std::vector<Channel>& channels) const;
  void finish(std::vector<Channel>& channels, const Slot& slot, std::uint32_t interface0, std::uint8_t data);
  void learn_modes(unsigned channel, const PassthroughStep& step, std::uint32_t interface0);
  void describe_failures(std::vector<Channel>& channels);

  std::shared_ptr<Lbp16Transport> bus_;
  unsigned sserial_port_;
  std::uint8_t mask_;
  PassthroughOptions options_;
  BoardIdentity board_{};
  std::string board_name_{};
  std::unique_ptr<SslbpPort> sslbp_;
  SslbpParameters parameters_{};
  HostActivity activity_{};
  std::vector<RemoteInfo> remotes_ = std::vector<RemoteInfo>(kMaxChannels);
  std::vector<std::uint32_t> bauds_ = std::vector<std::uint32_t>(kMaxChannels, 0);
  // The NV access mode of each channel's 8I20 as far as we know (0xEC steps done).
  std::vector<std::optional<std::uint8_t>> nv_modes_ = std::vector<std::optional<std::uint8_t>>(kMaxChannels);
  // RPC memory access (0xEA) each channel's finished commands asked for (nullopt: unknown).
  std::vector<std::optional<std::uint8_t>> rpc_modes_ =
      std::vector<std::optional<std::uint8_t>>(kMaxChannels);
  std::vector<std::string> notes_{};
  bool needs_resync_ = false;
  // A DOIT found a channel not ready (the port left setup mode: the card reset): the next
  // resync starts the port again.
  bool port_left_setup_ = false;
  std::chrono::microseconds slack_{0};  // learnt from late DOITs, added to every WaituS
  // RXUDPCount at our last look and our packets by then: any difference at the next look
  // is another host's (require_no_foreign_packets).
  std::uint16_t last_received_ = 0;
  std::uint64_t sent_at_last_ = 0;
  std::uint64_t missing_ours_ = 0;  // our packets the card had not counted at the last look
  // Another host talked to the card during our exchanges (or was found running at a
  // restart): closing must not stop a port that host may have started since.
  bool other_host_seen_ = false;

  mutable std::mutex execute_mutex_;  // one execute at a time on the wire
  PassthroughStats stats_;            // under execute_mutex_

  // Combines the links' batches into execute()s (after options_: it reads the window).
  CommandCombiner combiner_{[this](std::span<const Batch> batches) { return execute(batches); },
                            options_.gather_window};
};

}  // namespace i20::eth
