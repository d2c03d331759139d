#include "procs/launcher/launcher.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>

#include "base/log.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::launcher {
namespace {

// How long past a remote process's SIGKILL the launcher waits for its deputy to confirm the exit.
constexpr double kRemoteStopGraceS = 5.0;

// The launcher's monotonic clock [s].
double NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void Say(const Note& note) {
  if (!note.text.empty() && note.level >= GetLogLevel()) internal::LogLine(note.level) << note.text;
}

}  // namespace

Launcher::Launcher(const CommonFlags& flags, LaunchSpec spec, std::string bin_dir, std::string host,
                   std::string log_dir)
    : flags_(flags),
      plan_(std::move(spec), host),
      bin_dir_(std::move(bin_dir)),
      host_(std::move(host)),
      log_dir_(std::move(log_dir)),
      process_(flags),
      deputies_(&process_, plan_.spec().name + "@" + host_ + "/" + std::to_string(getpid()), NowMicros(),
                RunFolderName(log_dir_)) {
  for (const LaunchPlan::Entry& e : plan_.entries()) children_.push_back(MakeChild(e));
  process_.Subscribe<orbed::process_status_t>(
      channels::kProcessStatus, [this](const orbed::process_status_t& status, const std::string&, int64_t) {
        // A process saying it is stopping (e.g. the last heartbeat of a dying instance) is not ready.
        if (status.state != orbed::process_status_t::STATE_STARTING &&
            status.state != orbed::process_status_t::STATE_RUNNING) {
          return;
        }
        for (const Note& note : plan_.OnHeartbeat(
                 status.name, status.pid, status.host, [this](size_t i) { return children_[i]->running(); },
                 [this](size_t i) { return static_cast<int64_t>(children_[i]->pid()); }, NowS())) {
          Say(note);
        }
      });
  process_.AddTimer(0.02, [this] { Tick(); });
}

std::unique_ptr<ChildHandle> Launcher::MakeChild(const LaunchPlan::Entry& e) {
  if (e.remote)
    return deputies_.MakeChild(e.spec.host, e.spec.name, e.spec.stop_signal, e.spec.stop_timeout_s);
  return std::make_unique<Child>();
}

Launcher::~Launcher() = default;

bool Launcher::StartProcess(size_t i) {
  LaunchPlan::Entry& e = plan_.entries()[i];
  // Remote: the deputy expands ${ORBED_LOG_DIR} to its own run folder (else to this host's path).
  const ChildCommand command =
      plan_.Command(e, !e.remote || deputies_.run_dir().empty(), log_dir_, flags_.lcm_url);
  std::string error;
  children_[i] = MakeChild(e);
  if (!children_[i]->Start(command.argv, command.env, bin_dir_, &error)) {
    e.last_exit = error;
    ORBED_LOG(kError) << e.spec.name << ": " << error;
    return false;
  }
  plan_.Started(&e, NowS());
  if (e.remote) {
    ORBED_LOG(kInfo) << "asked deputy " << e.spec.host << " to start " << e.spec.name;
  } else {
    ORBED_LOG(kInfo) << "started " << e.spec.name << " (pid " << children_[i]->pid() << ")";
  }
  return true;
}

void Launcher::StartGroup(size_t group) {
  plan_.BeginGroup(group, NowS());
  ORBED_LOG(kInfo) << "starting group '" << plan_.spec().groups[group].name << "'";
  for (size_t i = 0; i < plan_.entries().size(); ++i) {
    LaunchPlan::Entry& e = plan_.entries()[i];
    if (e.group != group || StartProcess(i)) continue;
    const std::string failure = plan_.CouldNotStart(&e);
    if (!failure.empty()) return FailTestbed(failure);
  }
}

void Launcher::HandleExit(size_t i) {
  LaunchPlan::Entry& e = plan_.entries()[i];
  ChildHandle& child = *children_[i];
  child.Drain(e.prefix, true);
  const LaunchPlan::ExitVerdict verdict = plan_.OnExit(&e, child.exit_code(), child.term_signal(),
                                                       child.DescribeExit(), child.last_line(), NowS());
  if (verdict.action == LaunchPlan::ExitVerdict::Action::kFail) return FailTestbed(verdict.note.text);
  Say(verdict.note);
  if (verdict.action == LaunchPlan::ExitVerdict::Action::kStopAll) process_.RequestStop();
}

void Launcher::FailTestbed(const std::string& reason) {
  ORBED_LOG(kError) << reason;
  process_.SetLastError(reason);
  plan_.Fail();
  process_.RequestStop();
}

void Launcher::Tick() {
  deputies_.Tick();
  if (!plan_.stopping() && plan_.exit_code() == 0) {
    const std::string lost = deputies_.LostDeputy();
    if (!lost.empty()) {
      return FailTestbed(
          "deputy " + lost +
          " stopped following this launch (it heard nothing from it for its --orphan-timeout-s, "
          "or a later launch took it over) and stopped its processes");
    }
  }
  for (size_t i = 0; i < plan_.entries().size(); ++i) {
    LaunchPlan::Entry& e = plan_.entries()[i];
    if (!e.started) continue;
    children_[i]->Drain(e.prefix);
    if (children_[i]->running() && children_[i]->Poll()) HandleExit(i);
    if (plan_.RespawnDue(e, NowS())) {
      ++e.restarts;
      if (!StartProcess(i)) plan_.RespawnFailed(&e, NowS());
    }
  }
  if (plan_.stopping() || plan_.exit_code() != 0) return;
  // Readiness of respawned processes in the groups already up, then of the group being started.
  const std::string respawn_failure = plan_.RespawnTimeout(NowS());
  if (!respawn_failure.empty()) return FailTestbed(respawn_failure);
  if (plan_.all_started()) return;
  const LaunchPlan::GroupCheck check = plan_.CheckGroup(
      NowS(), [this](const std::string& host) { return deputies_.Heard(host); }, flags_.lcm_url);
  if (!check.failure.empty()) return FailTestbed(check.failure);
  if (!check.ready) return;
  ORBED_LOG(kInfo) << "group '" << plan_.spec().groups[plan_.starting_group()].name << "' ready after "
                   << NowS() - plan_.group_started_at_s() << " s";
  if (plan_.NextGroup()) return StartGroup(plan_.starting_group() + 1);
  ORBED_LOG(kInfo) << "testbed '" << plan_.spec().name << "' is up (" << NowS() - launch_started_at_s_
                   << " s)";
}

void Launcher::StopEverything() {
  plan_.BeginStop();
  std::vector<LaunchPlan::Entry>& entries = plan_.entries();
  for (size_t g = plan_.spec().groups.size(); g-- > 0;) {
    std::vector<size_t> group;
    for (size_t i = 0; i < entries.size(); ++i) {
      if (entries[i].group == g && entries[i].started && children_[i]->running()) group.push_back(i);
    }
    if (group.empty()) continue;
    ORBED_LOG(kInfo) << "stopping group '" << plan_.spec().groups[g].name << "'";
    double timeout = 0;
    for (size_t i : group) {
      children_[i]->Signal(entries[i].spec.stop_signal);
      timeout = std::max(timeout, entries[i].spec.stop_timeout_s);
    }
    deputies_.Tick();  // the remote stops go out now
    // A deputy not heard lately cannot confirm a stop: its processes are left to its orphan timeout.
    for (auto it = group.begin(); it != group.end();) {
      LaunchPlan::Entry& e = entries[*it];
      if (!e.remote || deputies_.Reachable(e.spec.host)) {
        ++it;
        continue;
      }
      ORBED_LOG(kWarn) << "deputy " << e.spec.host << " is not reachable: cannot confirm that " << e.spec.name
                       << " stops (its deputy stops it after its orphan timeout)";
      e.last_exit = "not confirmed stopped: deputy " + e.spec.host + " not reachable";
      it = group.erase(it);
    }
    const double begin_s = NowS();
    bool killed = false;
    for (;;) {
      bool any_running = false;
      for (size_t i : group) {
        children_[i]->Drain(entries[i].prefix);
        if (children_[i]->running() && !children_[i]->Poll()) any_running = true;
        if (!children_[i]->running()) entries[i].last_exit = children_[i]->DescribeExit();
      }
      if (!any_running) break;
      if (killed && NowS() - begin_s > timeout + kRemoteStopGraceS) {
        for (size_t i : group) {
          if (!children_[i]->running()) continue;
          ORBED_LOG(kWarn) << "deputy " << entries[i].spec.host << " did not confirm that "
                           << entries[i].spec.name << " stopped; leaving it to the deputy's orphan timeout";
          entries[i].last_exit = "not confirmed stopped by deputy " + entries[i].spec.host;
        }
        break;
      }
      if (!killed && NowS() - begin_s > timeout) {
        for (size_t i : group) {
          if (!children_[i]->running()) continue;
          ORBED_LOG(kWarn) << entries[i].spec.name << " did not stop within "
                           << entries[i].spec.stop_timeout_s << " s: SIGKILL";
          children_[i]->Signal(SIGKILL);
        }
        killed = true;
      }
      // Waits up to 10 ms for the deputies' statuses (and sends them the stops).
      deputies_.Tick();
      process_.lcm().handleTimeout(10);
    }
    for (size_t i : group) {
      children_[i]->Drain(entries[i].prefix, true);
      Say(plan_.StoppedWith(entries[i], children_[i]->exit_code()));
    }
  }
}

int Launcher::Run() {
  launch_started_at_s_ = NowS();
  ORBED_LOG(kInfo) << "launching '" << plan_.spec().name << "' from " << plan_.spec().path << " on "
                   << flags_.lcm_url;
  StartGroup(0);
  process_.Run();
  StopEverything();
  deputies_.SayGoodbye();
  std::fputs(plan_.Summary().c_str(), stdout);
  std::fflush(stdout);
  if (plan_.exit_code() != 0) ORBED_LOG(kError) << "testbed failed: exit code " << plan_.exit_code();
  return plan_.exit_code();
}

}  // namespace orbed::launcher
