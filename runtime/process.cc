#include "runtime/process.h"

#include <poll.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <limits>
#include <regex>
#include <stdexcept>
#include <thread>

#include "base/log.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed {
namespace {

std::atomic<bool> g_stop_signalled{false};

extern "C" void HandleStopSignal(int) { g_stop_signalled = true; }

std::chrono::steady_clock::duration Seconds(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

void InstallStopSignalHandlers() {
  struct sigaction action {};
  action.sa_handler = HandleStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: blocking calls return EINTR so loops notice promptly
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool StopSignalled() { return g_stop_signalled.load(); }
void RequestGlobalStop() { g_stop_signalled = true; }

std::string ThisHostName() {
  const char* host = std::getenv("ORBED_HOST");
  if (host != nullptr && host[0] != '\0') return host;
  char buffer[256] = {};
  if (gethostname(buffer, sizeof(buffer) - 1) != 0) return "unknown";
  return buffer;
}

namespace {

// Every process hears every datagram on the group, images included: without a large socket buffer
// a busy moment drops small messages too. 8 MB unless the URL says otherwise.
constexpr int64_t kDefaultRecvBufBytes = 8 << 20;

// How far (in periods) a timer may fall behind and still catch up tick by tick.
constexpr int kMaxCatchUpPeriods = 5;

std::string UrlWithReceiveBuffer(const std::string& url) {
  if (url.find("recv_buf_size=") != std::string::npos) return url;
  return WithRecvBufSize(url, kDefaultRecvBufBytes);
}

}  // namespace

Process::Process(const CommonFlags& flags)
    : name_(flags.name),
      seed_(flags.seed),
      duration_sec_(flags.duration_s),
      lcm_(std::make_unique<lcm::LCM>(UrlWithReceiveBuffer(flags.lcm_url))),
      start_(std::chrono::steady_clock::now()),
      sim_time_(flags.sim_time),
      sim_clock_arm_(flags.sim_clock_arm) {
  // Before any slow set-up (models, meshes, hashes), so that a stop request during it is a clean
  // stop (Run() returns at once) rather than the default action.
  InstallStopSignalHandlers();
  if (!lcm_->good()) {
    throw std::runtime_error("cannot open LCM at '" + flags.lcm_url +
                             "' (is there a multicast route? run inside `scripts/orbed launch` or "
                             "add one: ip route add 224.0.0.0/4 dev lo)");
  }
  AddWallTimer(1.0, [this] { PublishStatus(); });
  if (sim_time_) {
    Subscribe<orbed::sim_clock_t>(channels::ForArm(channels::kSimClock, flags.sim_clock_arm),
                                  [this](const orbed::sim_clock_t& msg, const std::string& channel, int64_t) {
                                    OnSimClock(msg, channel);
                                  });
    // Its timers wait for the sim: say so while there is none, and fail when none came at all
    // (a held sim sends SIM_CLOCK too).
    AddWallTimer(5.0, [this] {
      if (sim_clock_.started()) return;
      if (UptimeSeconds() >= kSimClockStartTimeoutS) {
        return Fail("no " + channels::ForArm(channels::kSimClock, sim_clock_arm_) + " within " +
                    std::to_string(static_cast<int>(kSimClockStartTimeoutS)) +
                    " s (--sim-time): is orbed-iiwa-sim running?");
      }
      ORBED_LOG(kWarn) << "no " << channels::ForArm(channels::kSimClock, sim_clock_arm_)
                       << " yet (--sim-time): the timers wait for orbed-iiwa-sim's clock";
    });
  }
  const ChaosSpec chaos = ParseChaosSpec(flags.chaos);
  if (chaos.active()) {
    chaos_ = std::make_unique<ChaosQueue>(chaos, name_);
    ORBED_LOG(kWarn) << "chaos: fault injection on received datagrams: " << FormatChaosSpec(chaos);
  }
}

Process::~Process() = default;

void Process::AddTimer(double period_s, std::function<void()> callback, const std::string& name) {
  AddTimerOn(sim_time_, period_s, std::move(callback), name);
}

void Process::AddWallTimer(double period_s, std::function<void()> callback, const std::string& name) {
  AddTimerOn(false, period_s, std::move(callback), name);
}

void Process::AddWallPoll(double period_s, std::function<void()> callback) {
  AddTimerOn(false, period_s, std::move(callback), "", /*poll=*/true);
}

void Process::AddTimerOn(bool sim, double period_s, std::function<void()> callback, const std::string& name,
                         bool poll) {
  if (!(period_s > 0) || !std::isfinite(period_s) || period_s > 1e6) {
    throw std::invalid_argument("timer period must be > 0 s (and at most 1e6 s)");
  }
  Timer timer;
  timer.sim = sim;
  timer.poll = poll;
  timer.drop_key = "timer/" + (name.empty() ? std::to_string(timers_.size()) : name);
  timer.period_ns = std::max<int64_t>(1, std::llround(period_s * 1e9));
  timer.next_ns = (sim ? sim_clock_.elapsed_us() * 1000 : UptimeNanos()) + timer.period_ns;
  timer.callback = std::move(callback);
  timers_.push_back(std::move(timer));
}

int64_t Process::UptimeNanos() const {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start_)
      .count();
}

int64_t Process::TimerNow(const Timer& timer) const {
  if (!timer.sim) return UptimeNanos();
  return sim_clock_.started() ? sim_clock_.elapsed_us() * 1000 : std::numeric_limits<int64_t>::min();
}

double Process::ClockSeconds() const {
  if (!sim_time_) return UptimeSeconds();
  return sim_deadline_ns_ ? 1e-9 * static_cast<double>(*sim_deadline_ns_) : sim_clock_.elapsed_s();
}

int64_t Process::ClockUtime() const {
  if (!sim_time_ || !sim_clock_.started()) return NowMicros();
  return sim_deadline_ns_ ? sim_clock_.UtimeAt(*sim_deadline_ns_) : sim_clock_.utime();
}

void Process::OnSimClock(const orbed::sim_clock_t& msg, const std::string& channel) {
  const std::string problem = CheckSimClock(msg);
  if (!problem.empty()) return Reject(channel + "/field", problem);
  const int64_t before = sim_clock_.utime();
  switch (sim_clock_.Advance(msg.utime, msg.start_utime)) {
    case SimClock::Step::kFirst:
      ORBED_LOG(kInfo) << "following the sim clock (" << channel << ", " << msg.realtime_rate
                       << "x real time)";
      break;
    case SimClock::Step::kRestarted:
      ORBED_LOG(kWarn) << "the sim restarted (" << channel << " from a new start " << msg.start_utime
                       << "): the clock goes on from its stamps";
      break;
    case SimClock::Step::kLate:
      // A delayed or reordered datagram: counted, not a step back.
      Reject(channel + "/late", "stamp " + std::to_string(msg.utime) + " is " +
                                    std::to_string(before - msg.utime) + " us behind the latest");
      break;
    case SimClock::Step::kJumped:
      // A stamp from nowhere: counted and logged, the clock goes on from it without advancing.
      Reject(channel + "/jump", "sim clock jumped by " + std::to_string(msg.utime - before) +
                                    " us; going on from the new stamp without advancing");
      break;
    case SimClock::Step::kAdvanced:
    case SimClock::Step::kSame:
      break;
  }
  // A lockstep round is answered once the timers it made due have run (Run()); a late one is not.
  if (msg.lockstep_round >= 1 && sim_clock_.utime() == msg.utime) unanswered_round_ = msg;
}

void Process::AnswerLockstepRound() {
  if (!unanswered_round_) return;
  orbed::sim_clock_ack_t ack{};
  ack.utime = unanswered_round_->utime;
  ack.start_utime = unanswered_round_->start_utime;
  ack.lockstep_round = unanswered_round_->lockstep_round;
  ack.process = name_;
  // The sim re-sends a round whose answers are missing: a repeat of the round answered last gets
  // that answer again ("published" included: the first may be the one that was lost). What was
  // published since stays for the next round's answer: the sim may have closed this round already
  // (another follower's answer was the missing one) and then ignores answers to it, so a flag
  // spent here would be lost and the round that follows would look quiet while the publication is
  // still being handled.
  const bool repeat = ack.utime == last_answer_.utime && ack.start_utime == last_answer_.start_utime &&
                      ack.lockstep_round == last_answer_.lockstep_round;
  ack.published = repeat ? last_answer_.published : published_since_ack_.exchange(false);
  unanswered_round_.reset();
  last_answer_ = ack;
  PublishControl(channels::ForArm(channels::kSimClockAck, sim_clock_arm_), ack);
}

lcm::Subscription* Process::Add(std::unique_ptr<SubscriptionBase> subscription, const std::string& channel) {
  subscription->process = this;
  subscription->index = static_cast<int>(subscriptions_.size());
  lcm::Subscription* lcm_subscription =
      lcm_->subscribe(channel, &SubscriptionBase::OnRaw, subscription.get());
  subscriptions_.push_back(std::move(subscription));
  return lcm_subscription;
}

void Process::Receive(SubscriptionBase* subscription, const lcm::ReceiveBuffer* rbuf,
                      const std::string& channel) {
  if (!chaos_ || !chaos_->Applies(channel)) {
    subscription->Deliver(*rbuf, channel);
    return;
  }
  const auto* bytes = static_cast<const uint8_t*>(rbuf->data);
  chaos_->Receive(
      {subscription->index, channel, std::vector<uint8_t>(bytes, bytes + rbuf->data_size), rbuf->recv_utime},
      UptimeSeconds());
  DeliverDueDatagrams();
}

void Process::DeliverDueDatagrams() {
  if (!chaos_) return;
  for (ChaosQueue::Datagram& datagram : chaos_->TakeDue(UptimeSeconds())) {
    lcm::ReceiveBuffer rbuf{datagram.data.data(), static_cast<uint32_t>(datagram.data.size()),
                            datagram.recv_utime};
    subscriptions_[datagram.target]->Deliver(rbuf, datagram.channel);
  }
}

lcm::Subscription* Process::SubscribeRaw(
    const std::string& channel_regex,
    std::function<void(const lcm::ReceiveBuffer&, const std::string&)> handler) {
  // LCM 1.3.1 hands back a subscription even when it cannot compile the regex, and crashes on its
  // first use: check the expression first (ECMAScript is close enough to LCM's PCRE to catch
  // malformed ones).
  try {
    std::regex check(channel_regex);
  } catch (const std::regex_error& e) {
    throw std::invalid_argument("invalid channel regular expression '" + channel_regex + "': " + e.what());
  }
  auto sub = std::make_unique<RawSubscription>();
  sub->handler = std::move(handler);
  return Add(std::move(sub), channel_regex);
}

void Process::SetLastError(const std::string& error) {
  std::lock_guard<std::mutex> lock(error_mutex_);
  last_error_ = error;
}

void Process::Fail(const std::string& error) {
  ORBED_LOG(kError) << error;
  SetLastError(error);
  failed_ = true;
  stop_requested_ = true;
}

void Process::CountDrop(const std::string& key, int64_t count) {
  if (count <= 0) return;
  int64_t before = 0, after = 0;
  {
    std::lock_guard<std::mutex> lock(drop_mutex_);
    const bool known = drops_.count(key) > 0 || drops_.size() < kMaxRejectionClasses - 1;
    int64_t& counter = drops_[known ? key : kOtherRejectionClass];
    before = counter;
    after = counter += count;
    dropped_ += count;
  }
  if (before == 0 || before / 1000 != after / 1000) {
    ORBED_LOG(kWarn) << "dropped under load: " << key << " " << after << " so far";
  }
}

std::map<std::string, int64_t> Process::drop_counts() const {
  std::lock_guard<std::mutex> lock(drop_mutex_);
  return drops_;
}

int64_t Process::dropped() const {
  std::lock_guard<std::mutex> lock(drop_mutex_);
  return dropped_;
}

double Process::UptimeSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

orbed::process_status_t Process::MakeStatus() const {
  orbed::process_status_t status{};
  status.utime = NowMicros();
  status.name = name_;
  status.pid = static_cast<int32_t>(getpid());
  status.host = host_;
  if (failed_) {
    status.state = orbed::process_status_t::STATE_FAILED;
  } else if (stop_requested_ || StopSignalled()) {
    status.state = orbed::process_status_t::STATE_STOPPING;
  } else if (running_) {
    status.state = orbed::process_status_t::STATE_RUNNING;
  } else {
    status.state = orbed::process_status_t::STATE_STARTING;
  }
  status.uptime_s = UptimeSeconds();
  status.messages_in = messages_in_;
  status.messages_out = messages_out_;
  status.rejected_inputs = rejections_.total();
  for (const auto& [reason, count] : rejections_.counts()) {
    status.reject_reason.push_back(reason);
    status.reject_count.push_back(count);
  }
  status.num_reasons = static_cast<int32_t>(status.reject_reason.size());
  {
    std::lock_guard<std::mutex> lock(drop_mutex_);
    status.dropped = dropped_;
    for (const auto& [reason, count] : drops_) {
      status.drop_reason.push_back(reason);
      status.drop_count.push_back(count);
    }
    status.num_drop_reasons = static_cast<int32_t>(status.drop_reason.size());
  }
  std::lock_guard<std::mutex> lock(error_mutex_);
  status.last_error = last_error_.empty() ? rejections_.last_reason() : last_error_;
  return status;
}

void Process::PublishStatus() {
  const orbed::process_status_t status = MakeStatus();
  PublishControl(channels::kProcessStatus, status);
}

void Process::RunTimer(size_t i) {
  Timer& timer = timers_[i];
  if (timer.sim) sim_deadline_ns_ = timer.next_ns;
  try {
    timer.callback();
  } catch (const std::exception& e) {
    // A bug or a bad input surfacing in a periodic task must not end the process.
    Reject("timer/" + std::to_string(i), std::string("exception: ") + e.what());
  }
  sim_deadline_ns_.reset();
  const int64_t now_ns = TimerNow(timer);
  timer.next_ns += timer.period_ns;
  // A few periods late (a busy moment, or a sim tick of several periods): the missed ticks run
  // back to back, so a 200 Hz stream keeps its average rate. Further behind (a stall): they are
  // skipped, not bunched.
  // A sim timer catches up over the whole last SIM_CLOCK step too (R x P of sim time at once).
  const int64_t allowed_ns =
      kMaxCatchUpPeriods * timer.period_ns + (timer.sim ? sim_clock_.last_step_us() * 1000 : 0);
  if (timer.poll && now_ns >= timer.next_ns) {
    timer.next_ns += ((now_ns - timer.next_ns) / timer.period_ns + 1) * timer.period_ns;
  } else if (now_ns - timer.next_ns > allowed_ns) {
    const int64_t behind = (now_ns - timer.next_ns) / timer.period_ns + 1;
    timer.next_ns += behind * timer.period_ns;
    CountDrop(timer.drop_key, behind);
  }
}

int Process::Run() {
  InstallStopSignalHandlers();
  running_ = true;
  ORBED_LOG(kInfo) << "running (pid " << getpid() << ")";
  PublishStatus();  // the first heartbeat tells the launcher we are ready
  const auto deadline =
      duration_sec_ > 0 ? start_ + Seconds(duration_sec_) : std::chrono::steady_clock::time_point::max();
  // Waits are capped so that a stop request is noticed within 50 ms.
  const auto max_wait = std::chrono::milliseconds(50);
  while (!stop_requested_ && !StopSignalled()) {
    if (std::chrono::steady_clock::now() >= deadline) {
      ORBED_LOG(kInfo) << "--duration-s reached";
      break;
    }
    // The monotonic timers, each once if due; then the sim timers in the order of their deadlines
    // (a SIM_CLOCK may have made several due), as they would have run at real time.
    for (size_t i = 0; i < timers_.size(); ++i) {
      if (!timers_[i].sim && TimerNow(timers_[i]) >= timers_[i].next_ns) RunTimer(i);
    }
    while (sim_clock_.started()) {
      std::optional<size_t> first;
      for (size_t i = 0; i < timers_.size(); ++i) {
        const Timer& timer = timers_[i];
        if (timer.sim && TimerNow(timer) >= timer.next_ns &&
            (!first || timer.next_ns < timers_[*first].next_ns)) {
          first = i;
        }
      }
      if (!first) break;
      RunTimer(*first);
    }
    AnswerLockstepRound();
    DeliverDueDatagrams();
    const auto now = std::chrono::steady_clock::now();
    auto next = std::min(deadline, now + max_wait);
    for (const Timer& timer : timers_) {
      // A sim timer already due runs at once; the others wait for the next SIM_CLOCK.
      if (!timer.sim) {
        next = std::min(next, start_ + std::chrono::nanoseconds(timer.next_ns));
      } else if (TimerNow(timer) >= timer.next_ns) {
        next = now;
      }
    }
    if (chaos_ && std::isfinite(chaos_->NextDue()))
      next = std::min(next, start_ + Seconds(chaos_->NextDue()));
    const auto wait_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(next - now).count();
    // Wait on LCM's file descriptor with ppoll (nanosecond timeout) rather than handleTimeout,
    // whose millisecond rounding would make a 1 kHz timer drift late and skip ticks.
    pollfd fd{lcm_->getFileno(), POLLIN, 0};
    timespec timeout{};
    if (wait_ns > 0) {
      timeout.tv_sec = static_cast<time_t>(wait_ns / 1000000000);
      timeout.tv_nsec = static_cast<long>(wait_ns % 1000000000);
    }
    const int ready = ppoll(&fd, 1, &timeout, nullptr);
    const int result = ready > 0 ? lcm_->handleTimeout(0) : 0;
    if (result < 0 && !StopSignalled()) {
      SetLastError("LCM handle failed");
      ORBED_LOG(kWarn) << "LCM handleTimeout failed";
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  running_ = false;
  stop_requested_ = true;
  PublishStatus();  // says STOPPING (or FAILED)
  ORBED_LOG(kInfo) << "stopped: " << messages_in_ << " in, " << messages_out_ << " out, "
                   << rejections_.total() << " rejected";
  if (chaos_) ORBED_LOG(kInfo) << "chaos: " << FormatChaosCounts(chaos_->counts());
  return failed_ ? 1 : 0;
}

}  // namespace orbed
