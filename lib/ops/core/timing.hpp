// SPDX-License-Identifier: GPL-2.0-or-later
// Every count and every timeout the programs use, set here: how often a byte is sent and
// how long anything may wait, per path. The layers below ops keep the mechanisms (resend a
// read-only packet, fence, replay, poll) and take their figures from the options built
// here: every count and wait in their option structs is a link::Given, which has no
// default, so a lower layer cannot be built without its figures (link/given.hpp). The
// budget per exchange and the operation's deadline are ops' RetryPolicy (retry.hpp), spent
// in Amp::with_retries and Amp::wait_for_answer.
//
// What one lost exchange costs, worst case (the README's "How long a command may take";
// the figures are proved by OperationDeadline.* in tests/eth/retry_budget_test.cpp):
// - ops, both paths: RetryPolicy::attempts sends, then one probe per probe_interval until
//   silence_window after the first unanswered one. The operation's deadline counts from
//   the start of the card's opening; every wait ends by it (link::WaitBound) and past it
//   nothing is sent but the way back: restores within kSettleBudget after it, leaving NV
//   access or RPC memory mode within kLeaveModeBudget of its own. A write is sent once; a
//   read-back decides.
// - serial link: each batch once (ops repeats), waiting --timeout + the wire time.
// - passthrough packet: once (ops repeats), waiting the UDP reply timeout (from --timeout,
//   backed off up to kUdpMaxTimeout) plus its WaituS; a lost packet with writes is fenced:
//   read-only probes for up to kFenceBound. Late DOITs: replayed at most kMaxReplays times.
//   Closing the port: its SSLBP stop within kPortCloseBudget.
// - the Ethernet layers' own exchanges (opening, SSLBP commands, IDROM): read-only packets
//   and SSLBP commands a probe found not run, RetryPolicy::attempts sends each; an SSLBP
//   command is polled for up to kSslbpCommandTimeout.
// - the running-host watch: kRunningHostWindow, and up to kRunningHostExtraWindows more; a
//   counter read repeated up to kCounterReadAttempts times when a resend doubled its
//   request; in a take-over, kTakeOverSetupStarts setup starts per channel.
// - --passive: one send per read, waiting max(--timeout, kPassiveReadFloor).
// - normal mode: one DOIT per period (watch, console: kNormalModePeriod, reply within
//   kNormalModeReply; commissioning: its period, reply within two periods); the session
//   ends after kNormalModeMissedCycles cycles in a row without a reply.
// - 8I20 reset: answered again within kResetWait; CLEARFAULT cleared within kClearFaultWait.
#pragma once

#include <chrono>
#include <optional>

// Only declared here: retry.hpp and endpoint.hpp take their defaults from this file.
namespace i20::ops {
struct LinkSettings;
struct RetryPolicy;
}  // namespace i20::ops

namespace i20::link {
struct PipelinedLinkOptions;
struct SerialOptions;
}  // namespace i20::link
namespace i20::device {
struct AmpTiming;
}
namespace i20::eth {
struct UdpOptions;
struct FenceOptions;
struct SslbpOptions;
struct RunningHostCheck;
struct PassthroughOptions;
struct ScanOptions;
struct PassiveOptions;
struct NormalModeOptions;
}  // namespace i20::eth

namespace i20::ops::timing {

// The retry budget's defaults (RetryPolicy, retry.hpp): sends of one exchange in all, how
// long a card that stopped answering is waited for and how often it is asked again in that
// time, and the operation's own deadline from the moment its card is opened.
inline constexpr unsigned kAttempts = 3;
inline constexpr std::chrono::milliseconds kSilenceWindow{2000};
inline constexpr std::chrono::milliseconds kProbeInterval{100};
inline constexpr std::chrono::milliseconds kOperationDeadline{20000};
// After the operation's deadline, only the way back is sent: the restores of a change that
// did not finish (each sent once and read back) within kSettleBudget, then leaving NV access
// or RPC memory mode within kLeaveModeBudget from the moment it starts, however long the
// restores took. With a fence after a lost write (kFenceBound) these bound a command:
// README's "How long a command may take".
inline constexpr std::chrono::milliseconds kSettleBudget{10000};
inline constexpr std::chrono::milliseconds kLeaveModeBudget{5000};
// Closing an Ethernet port after the command: its SSLBP stop, best effort (setup mode drives
// no motor), within this however long the command took.
inline constexpr std::chrono::milliseconds kPortCloseBudget{1000};
// The serial link's reply timeout on top of the wire time (--timeout's default), and setup
// mode's baud rate (always 115200, manual).
inline constexpr unsigned kReplyTimeoutMs = 50;
inline constexpr unsigned kSetupBaud = 115200;

// The serial link's own bounds: how long draining a card that keeps talking may go on past
// the quiet time (after a garbled reply), how long past its wire time a write may take
// before the driver counts as hung, and how long asio may take to deliver a cancellation.
inline constexpr std::chrono::milliseconds kSerialMaxDrain{500};
inline constexpr std::chrono::milliseconds kSerialWriteSlack{2000};
inline constexpr std::chrono::milliseconds kSerialCancelGrace{200};
// The longest wait for one UDP reply, back-off included: what a dead card costs per send.
inline constexpr std::chrono::milliseconds kUdpMaxTimeout{1000};
// How long after its last send a passthrough packet with writes may still reach the card
// (a congested switch held one back 400 ms, issue 18); only paid for a lost request.
inline constexpr std::chrono::milliseconds kFenceBound{1000};
inline constexpr std::chrono::milliseconds kFenceProbePause{2};
inline constexpr std::chrono::milliseconds kFenceMaxProbePause{20};
// An SSLBP start probes every selected channel and "may be many mS" (manual): 2 s.
inline constexpr std::chrono::milliseconds kSslbpCommandTimeout{2000};
// Pause between read-back polls of a slow SSLBP command, and the WaituS after a local
// parameter request or a stop (SSLBP answers those in microseconds).
inline constexpr std::chrono::microseconds kSslbpPollPause{250};
inline constexpr std::chrono::microseconds kSslbpLocalSettle{50};
// Late DOITs one execute() replays before the link reports the remote too slow.
inline constexpr unsigned kMaxReplays = 16;
// The passthrough's packing: the most WaituS one packet may ask for (the card answers only
// after it), the most extra wait per DOIT learnt from late ones, and how long a channel's
// link waits for the other channels' links to join its packet.
inline constexpr std::chrono::milliseconds kPassthroughMaxPacketWait{50};
inline constexpr std::chrono::milliseconds kPassthroughMaxSlack{20};
inline constexpr std::chrono::microseconds kPassthroughGatherWindow{2000};
// Longer than the 8I20's 40 ms watchdog, so a host that keeps an 8I20 running always shows
// (RunningHostCheck::window explains the figure).
inline constexpr std::chrono::milliseconds kRunningHostWindow{45};
// COMMAND reads spread over the window, and windows added while a few foreign packets were
// seen (a slow host and a stray query look alike in one window).
inline constexpr unsigned kRunningHostCommandSamples = 4;
inline constexpr unsigned kRunningHostExtraWindows = 2;
// Counter reads repeated because the request went out more than once (a late reply).
inline constexpr unsigned kCounterReadAttempts = 4;
// Setup starts per channel in a take-over (--take-over), where the other host's DOITs can
// land inside ours; without a take-over a channel gets one.
inline constexpr unsigned kTakeOverSetupStarts = 4;
// The documented bound of --passive: at most this many UDP requests a second.
inline constexpr unsigned kPassiveMaxRequestsPerSecond = 20;
// One attempt per request of the passive reader, never shorter than this.
inline constexpr std::chrono::milliseconds kPassiveReadFloor{200};
// Normal mode for watch and the console: the DOIT period and its reply timeout.
inline constexpr std::chrono::milliseconds kNormalModePeriod{10};
inline constexpr std::chrono::milliseconds kNormalModeReply{20};
// Cycles in a row without a reply before a normal-mode session gives up: at least these, and
// at a short period as many as fill the 8I20's watchdog (below), so that a 1 ms loop does not
// give up on a card that a 6 ms hiccup of the host kept from answering.
inline constexpr unsigned kNormalModeMissedCycles = 3;
// The 8I20's watchdog in normal mode: "40 mS" (manual, 8I20 DEVICE SPECIFIC SETUP).
inline constexpr std::chrono::milliseconds kEightI20Watchdog{40};
// Commissioning's drive loop: cycles of QSETPOINT 0 it sends before it stops the port.
inline constexpr unsigned kZeroCyclesBeforeStop = 3;
// The time between two samples of `i20 watch` (also --passive) and of the console's live
// view, unless --interval says otherwise.
inline constexpr std::chrono::milliseconds kWatchInterval{200};
inline constexpr std::chrono::milliseconds kConsoleLiveInterval{100};
// The console's server: how often it asks whether to stop (Ctrl-C), how long it reads what a
// refused client still sends before closing, and how long a silent connection stays open.
inline constexpr std::chrono::milliseconds kConsoleStopPoll{50};
inline constexpr std::chrono::seconds kConsoleDrain{1};
inline constexpr std::chrono::seconds kConsoleIdle{30};
// The power-up `i20 hal` writes (docs/linuxcnc-hal.md, "Power-up and fault reset"): the
// smart-serial port runs this long after machine-on, when the 8I20's bus, switched on with the
// machine, has risen (LinuxCNC's Smithy sample configurations wait about a second too); its
// 8I20s' faults count this long after the port started, when hostmot2 has run the start and
// read each remote's fresh status.
inline constexpr std::chrono::milliseconds kHalPortRunDelay{1000};
inline constexpr std::chrono::milliseconds kHalFaultWatchDelay{500};
// A lost card is retried at the sample interval, but not more often than this: opening a
// vanished port or waiting out a timeout every 20 ms would only spin.
inline constexpr std::chrono::milliseconds kMonitorMinRetry{500};
// How fast a wait between samples notices Ctrl-C or its end (ops::sleep_until).
inline constexpr std::chrono::milliseconds kStopPollSlice{20};
// How long a reading waits for the normal-mode session's next sample (50 periods).
inline constexpr std::chrono::milliseconds kNormalModeSample{500};
// Commissioning (i20 commission): the drive loop's period, the sweep's align and ramp times
// and the whole run's time limit (defaults the command line may change), then the closed-loop
// check's own waits: how long each direction may push, the current's ramp to full, the rest
// between the two, and the hold at standstill with its ramp.
inline constexpr std::chrono::milliseconds kCommissionPeriod{10};
inline constexpr double kCommissionAlignS = 0.8;
inline constexpr double kCommissionRampS = 0.4;
inline constexpr double kCommissionTimeLimitS = 60;
inline constexpr double kCheckPushS = 1.5;
inline constexpr double kCheckRampS = 1.0;
inline constexpr double kCheckRestS = 0.3;
inline constexpr double kHoldRampS = 0.15;
inline constexpr double kHoldS = 0.4;
// tune-axis: its drive loop's period. The 8I20 keeps a DOIT's ANGLE until the next one, so at
// the identification move's speed a 10 ms period would commutate tens of electrical degrees
// off and the torque asked for would not be the torque given (LinuxCNC runs bldc every 1 ms).
inline constexpr std::chrono::milliseconds kIdentifyPeriod{1};
// Another host's packets commissioning tolerates in all (a stray mesaflash query; LinuxCNC
// sends one every servo period), the drive-loop cycles between two checks for one (each
// costs a read-only packet).
inline constexpr unsigned kCommissionForeignPackets = 2;
inline constexpr unsigned kCommissionHostCheckEvery = 20;
inline constexpr unsigned kCommissionHostCheckMisses = 3;
// The rotor's speed (the runaway guard) is measured over this span: five of commissioning's
// 10 ms periods, fifty of tune-axis's 1 ms ones (over five, a host's 5 ms hiccup doubled it).
inline constexpr std::chrono::milliseconds kCommissionSpeedSpan{50};
// How long an 8I20 may take to answer again after a reset, and to clear CLEARFAULT.
inline constexpr std::chrono::milliseconds kResetWait{3000};
inline constexpr std::chrono::milliseconds kClearFaultWait{1000};
// How often those are polled: the cookie after a reset, CLEARFAULT after writing it.
inline constexpr std::chrono::milliseconds kResetPoll{20};
inline constexpr std::chrono::milliseconds kClearFaultPoll{5};
// Sends of the batch that leaves NV access or RPC memory mode inside one device step (the
// first may fail right after the error that brought it there); ops' Amp::settle() asks
// again after it, within the retry budget and the silence window.
inline constexpr unsigned kLeaveModeTries = 2;

// The 8I20 client's own tries and poll pauses (device::Amp8i20).
device::AmpTiming amp();
// The serial link (3I21/3I22, the built-in simulator): each batch sent once, ops repeats.
link::PipelinedLinkOptions serial_link(const LinkSettings& settings, const RetryPolicy& retry);
// The serial port under it (3I21/3I22) at the user's baud.
link::SerialOptions serial_port(const LinkSettings& settings);
// The UDP client of a passthrough, a scan or a normal-mode session.
eth::UdpOptions udp(const LinkSettings& settings, const RetryPolicy& retry);
eth::FenceOptions fence();
eth::SslbpOptions sslbp(const RetryPolicy& retry);
eth::RunningHostCheck running_host(const LinkSettings& settings);
// The SSLBP setup-mode passthrough under an 8I20 command over Ethernet.
eth::PassthroughOptions passthrough(const LinkSettings& settings, const RetryPolicy& retry);
eth::ScanOptions scan(const LinkSettings& settings);
eth::ScanOptions scan(const LinkSettings& settings, const RetryPolicy& retry);
eth::PassiveOptions passive(const LinkSettings& settings);
// Normal mode at `period` (watch, the console, commissioning). The commissioning loop gives
// `reply` (two periods), so that a lost reply never costs the 8I20's 40 ms watchdog.
// `reply` bounds each reply's wait, back-off included, when given.
eth::NormalModeOptions normal_mode(const LinkSettings& settings,
                                   std::chrono::milliseconds period = kNormalModePeriod,
                                   std::optional<std::chrono::milliseconds> reply = std::nullopt);

}  // namespace i20::ops::timing
