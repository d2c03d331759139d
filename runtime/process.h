#pragma once
/// @file
/// The scaffold every orbed process runs on: one LCM instance, typed subscriptions that decode,
/// count and reject (a message that fails to decode is a counted rejection, never a silent drop),
/// periodic timers, the 1 Hz PROCESS_STATUS heartbeat, and a clean stop on SIGINT/SIGTERM or after
/// --duration-s.
///
/// Threading: Run() is a single-threaded loop. Message handlers and timers are called on the thread
/// that calls Run(), never concurrently with each other. Counters are atomic, so other threads a
/// process owns (e.g. the logger's writer) may count too. RequestStop() and the signal handler may
/// be called from any thread.
///
/// Clocks: uptime, --duration-s, the heartbeat and the fault injection's delays use the monotonic
/// clock, the heartbeat's utime the wall clock. The process clock (AddTimer, ClockSeconds,
/// ClockUtime) is the monotonic and the wall clock too, unless the process follows the sim clock
/// (CommonFlags::sim_time, --sim-time, AddSimTimeFlag): then it subscribes to SIM_CLOCK
/// (sim_clock.h), its timers fire when the sim time reaches their deadlines (none before the first
/// SIM_CLOCK), inside a timer's callback the clock reads that deadline (so a 60 Hz stream samples
/// at exact multiples of 1/60 s of sim time, however many sim steps one tick of the sim makes), and
/// elsewhere the latest SIM_CLOCK. The sim itself, the logger, the launcher and the monitor keep
/// the wall clock. A SIM_CLOCK of a lockstep round (lockstep_round >= 1, sim_clock.h) is answered
/// on SIM_CLOCK_ACK right after the timers it made due have run, before the next datagram is
/// handled, with whether the process published since its previous answer (Publish, not
/// PublishControl); the sim's repeat of a round already answered gets the same answer again, and
/// what was published meanwhile is said in the answer to the next round.
///
/// Fault injection: with a chaos spec (CommonFlags::chaos, i.e. --chaos or $ORBED_CHAOS;
/// runtime/chaos.h) every datagram of a matching channel passes, before decoding, through a
/// ChaosQueue seeded with the spec and the process name: it may be dropped, duplicated, delayed or
/// reordered. Delayed and held datagrams are delivered later from the Run() loop, on the same
/// thread, with their original receive utime. What was done is logged at start and at exit
/// ("chaos: N datagrams: ... dropped, ..."); it is not a rejection and not counted as one.
///
/// Drops under load: work a process could not do in time is counted, never silent, on its
/// heartbeat (process_status_t dropped / drop_reason / drop_count, contract change 3): a timer more
/// than a few periods behind skips deadlines, counted as "timer/<name>" per skipped deadline; a
/// process counts its own kinds with CountDrop (the headset's renderer: "<channel>/busy").

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>
#include <orbed/process_status_t.hpp>
#include <orbed/sim_clock_ack_t.hpp>

#include "lcmtypes/bounded_decode.h"
#include "lcmtypes/contract/validation.h"
#include "runtime/chaos.h"
#include "runtime/flags.h"
#include "runtime/sim_clock.h"

namespace orbed {

/// Exit code of a process that stopped because it cannot write its output (a full disk, a
/// read-only or vanished folder): the fault is outside the process and a new instance would meet
/// it again, so orbed-launch does not respawn it, whatever its `respawn:` says, and a required one
/// fails the launch with its last output line as the reason. (EX_IOERR of sysexits.h.)
inline constexpr int kExitCannotWrite = 74;

/// Installs SIGINT/SIGTERM handlers that make every Process::Run() return. Idempotent.
void InstallStopSignalHandlers();
/// True once SIGINT or SIGTERM arrived (or RequestGlobalStop() was called).
bool StopSignalled();
void RequestGlobalStop();

/// The host this process runs on, as its PROCESS_STATUS says: $ORBED_HOST when set and not empty
/// (orbed-launch sets it: its --host, or a deputy's name), else the machine's hostname.
std::string ThisHostName();

class Process {
 public:
  /// Connects to flags.lcm_url (adding recv_buf_size=8 MB unless the URL sets it); throws
  /// std::runtime_error naming the URL if LCM cannot start. Installs the SIGINT/SIGTERM handlers.
  explicit Process(const CommonFlags& flags);
  virtual ~Process();
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  const std::string& name() const { return name_; }
  uint64_t seed() const { return seed_; }
  lcm::LCM& lcm() { return *lcm_; }

  /// Subscribes `handler(msg, channel, receive_utime)` to `channel`. Every message (after the fault
  /// injection, if any) is decoded with DecodeBounded (lcmtypes/bounded_decode.h: array counts
  /// checked against the bytes before LCM's decode allocates); one that is not exactly a well-formed
  /// Msg is rejected under key "<channel>/decode/<why>" (why: truncated, fingerprint, count, string,
  /// trailing, ...).
  template <class Msg>
  void Subscribe(const std::string& channel,
                 std::function<void(const Msg&, const std::string&, int64_t)> handler);

  /// Subscribes to every channel matching `channel_regex` without decoding (for the logger and
  /// bridges). The handler gets LCM's receive buffer (data valid only during the call).
  /// Returns LCM's subscription so the caller can raise its queue capacity. Throws
  /// std::invalid_argument for a malformed regular expression.
  lcm::Subscription* SubscribeRaw(const std::string& channel_regex,
                                  std::function<void(const lcm::ReceiveBuffer&, const std::string&)> handler);

  /// Publishes and counts one message out (and says so on the next SIM_CLOCK_ACK: it may cause replies).
  template <class Msg>
  void Publish(const std::string& channel, const Msg& msg) {
    lcm_->publish(channel, &msg);
    ++messages_out_;
    published_since_ack_ = true;
  }
  /// Publishes and counts a message no process acts on within a sim tick (heartbeats, the sim clock
  /// and its answers, the headset's wall-clock image streams): not a publication a lockstep round
  /// waits on. Thread-safe as Publish.
  template <class Msg>
  void PublishControl(const std::string& channel, const Msg& msg) {
    lcm_->publish(channel, &msg);
    ++messages_out_;
  }
  /// Whether Publish() was called since the last call (or the last SIM_CLOCK_ACK); clears it. The
  /// sim, which answers no clock, asks this once per lockstep round.
  bool TakePublished() { return published_since_ack_.exchange(false); }

  /// Calls `callback` every `period_s` seconds of the process clock on the Run() thread, first at
  /// start + period (with sim_time: the first SIM_CLOCK + period, or now + period if later).
  /// Up to 5 missed ticks run back to back (the average rate holds through a busy moment); beyond
  /// that they are skipped, each skipped deadline a counted drop "timer/<name>" (`name` defaults
  /// to the timer's index). An exception from a callback is a counted rejection ("timer/<i>").
  /// Exceptions from message handlers likewise ("<channel>/handler"): the process keeps running.
  void AddTimer(double period_s, std::function<void()> callback, const std::string& name = "");
  /// As AddTimer, on the monotonic clock whether or not the process follows the sim clock.
  void AddWallTimer(double period_s, std::function<void()> callback, const std::string& name = "");
  /// A monotonic-clock poll: as AddWallTimer, but missed deadlines are neither run nor counted (the
  /// callback checks a condition; being late for it loses no work).
  void AddWallPoll(double period_s, std::function<void()> callback);

  /// Whether the process clock is the sim's (CommonFlags::sim_time).
  bool sim_time() const { return sim_time_; }
  /// The process clock [s] since the start: the monotonic seconds since construction, or with
  /// sim_time the sim seconds since the first SIM_CLOCK (0 before it; a sim timer's deadline inside
  /// its callback).
  double ClockSeconds() const;
  /// The process clock as a message stamp [µs since the epoch]: NowMicros(), or with sim_time the
  /// sim's stamp of ClockSeconds() (NowMicros() before the first SIM_CLOCK).
  int64_t ClockUtime() const;
  /// The sim clock this process follows (not started without sim_time).
  const SimClock& sim_clock() const { return sim_clock_; }

  /// Counts `count` units of work dropped under load under `key` (thread-safe; logged: the first of
  /// a key, then every 1000th). At most kMaxRejectionClasses keys, further ones under "other".
  void CountDrop(const std::string& key, int64_t count = 1);

  /// Records a rejected input with its class `key` and a reason; logs it (rate-limited).
  void Reject(const std::string& key, const std::string& reason) { rejections_.Reject(key, reason); }
  /// Records an error that is not a rejected input (shown as last_error on the heartbeat).
  void SetLastError(const std::string& error);

  /// Runs until a stop signal, RequestStop() or --duration-s. Returns the process exit code
  /// (0 unless Fail() was called).
  int Run();
  void RequestStop() { stop_requested_ = true; }
  /// Marks the process failed: the next heartbeat says STATE_FAILED and Run() returns 1.
  void Fail(const std::string& error);

  /// The heartbeat as it would be published now (for tests and the 1 Hz timer).
  orbed::process_status_t MakeStatus() const;
  int64_t messages_in() const { return messages_in_; }
  int64_t messages_out() const { return messages_out_; }
  const RejectionCounter& rejections() const { return rejections_; }
  /// Drops so far per key (CountDrop, skipped timer deadlines), and their sum.
  std::map<std::string, int64_t> drop_counts() const;
  int64_t dropped() const;
  double UptimeSeconds() const;
  /// The fault injection's queue, or nullptr when the process runs without one.
  const ChaosQueue* chaos() const { return chaos_.get(); }
  /// Delivers the delayed and held datagrams that are due now (the Run() loop does this; public so
  /// that tests driving LCM by hand can too).
  void DeliverDueDatagrams();

 private:
  // Deadlines in whole nanoseconds, so that timers of commensurate periods (20 and 30 ms) meet
  // exactly and run in the order they were added.
  struct Timer {
    bool sim{false};       // on the sim clock (else the monotonic one)
    bool poll{false};      // missed deadlines skipped silently (AddWallPoll)
    int64_t period_ns{0};  // of its clock
    int64_t next_ns{0};    // deadline on its clock: since the start / the first SIM_CLOCK
    std::function<void()> callback;
    std::string drop_key;  // "timer/<name>"
  };
  // One subscription: LCM calls OnRaw(), which hands the datagram to the process (Receive: the
  // fault injection, if any); Deliver() decodes into the typed handler, or passes the bytes on.
  struct SubscriptionBase {
    virtual ~SubscriptionBase() = default;
    void OnRaw(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
      process->Receive(this, rbuf, channel);
    }
    virtual void Deliver(const lcm::ReceiveBuffer& rbuf, const std::string& channel) = 0;
    Process* process{nullptr};
    int index{0};  // in subscriptions_
  };
  template <class Msg>
  struct TypedSubscription;
  struct RawSubscription;

  // Every datagram from LCM: straight to the subscription, or through the chaos queue.
  void Receive(SubscriptionBase* subscription, const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  // Registers a subscription (sets its process and index) and subscribes it to LCM.
  lcm::Subscription* Add(std::unique_ptr<SubscriptionBase> subscription, const std::string& channel);
  void PublishStatus();
  void AddTimerOn(bool sim, double period_s, std::function<void()> callback, const std::string& name,
                  bool poll = false);
  // Answers the lockstep round received last, if not yet answered (SIM_CLOCK_ACK).
  void AnswerLockstepRound();
  // Now on the timer's clock [ns]; INT64_MIN for a sim timer before the first SIM_CLOCK.
  int64_t TimerNow(const Timer& timer) const;
  int64_t UptimeNanos() const;
  // Runs timers_[i]'s callback (a sim timer's with the clock at its deadline) and sets its next
  // deadline, skipping (and counting) those more than kMaxCatchUpPeriods behind.
  void RunTimer(size_t i);
  void OnSimClock(const orbed::sim_clock_t& msg, const std::string& channel);

  std::string name_;
  std::string host_ = ThisHostName();
  uint64_t seed_;
  double duration_sec_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::vector<std::unique_ptr<SubscriptionBase>> subscriptions_;
  std::vector<Timer> timers_;
  std::chrono::steady_clock::time_point start_;
  bool sim_time_{false};
  std::string sim_clock_arm_;  // whose SIM_CLOCK (CommonFlags::sim_clock_arm)
  SimClock sim_clock_;
  std::optional<int64_t> sim_deadline_ns_;              // the running sim timer's deadline
  std::optional<orbed::sim_clock_t> unanswered_round_;  // a lockstep SIM_CLOCK not yet answered
  orbed::sim_clock_ack_t last_answer_{};                // the last answer sent (a repeat says as much)
  std::atomic<bool> published_since_ack_{false};
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
  std::atomic<bool> failed_{false};
  std::atomic<int64_t> messages_in_{0};
  std::atomic<int64_t> messages_out_{0};
  RejectionCounter rejections_;
  mutable std::mutex drop_mutex_;
  std::map<std::string, int64_t> drops_;  // guarded by drop_mutex_
  int64_t dropped_ = 0;                   // guarded by drop_mutex_
  std::unique_ptr<ChaosQueue> chaos_;     // null without a chaos spec
  mutable std::mutex error_mutex_;
  std::string last_error_;  // guarded by error_mutex_
};

template <class Msg>
struct Process::TypedSubscription : Process::SubscriptionBase {
  std::function<void(const Msg&, const std::string&, int64_t)> handler;
  void Deliver(const lcm::ReceiveBuffer& rbuf, const std::string& channel) override {
    ++process->messages_in_;
    Msg msg;
    const DecodeResult decoded = DecodeBounded(rbuf.data, rbuf.data_size, &msg);
    if (!decoded.ok()) {
      process->Reject(channel + "/decode/" + wire::KindName(decoded.kind),
                      "cannot decode " + std::to_string(rbuf.data_size) + " bytes as " + Msg::getTypeName() +
                          ": " + decoded.error);
      return;
    }
    try {
      handler(msg, channel, rbuf.recv_utime);
    } catch (const std::exception& e) {
      process->Reject(channel + "/handler", std::string("exception: ") + e.what());
    }
  }
};

struct Process::RawSubscription : Process::SubscriptionBase {
  std::function<void(const lcm::ReceiveBuffer&, const std::string&)> handler;
  void Deliver(const lcm::ReceiveBuffer& rbuf, const std::string& channel) override {
    ++process->messages_in_;
    try {
      handler(rbuf, channel);
    } catch (const std::exception& e) {
      process->Reject(channel + "/handler", std::string("exception: ") + e.what());
    }
  }
};

template <class Msg>
void Process::Subscribe(const std::string& channel,
                        std::function<void(const Msg&, const std::string&, int64_t)> handler) {
  auto sub = std::make_unique<TypedSubscription<Msg>>();
  sub->handler = std::move(handler);
  Add(std::move(sub), channel);
}

}  // namespace orbed
