#include "procs/launcher/launcher.h"

#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "base/format.h"
#include "base/log.h"
#include "base/run_folder.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/launcher/deputy_protocol.h"

namespace orbed::launcher {
namespace {

// How long past a remote process's SIGKILL the launcher waits for its deputy to confirm the exit.
constexpr double kRemoteStopGraceS = 5.0;

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

namespace {

// A process placed on another host must fit DEPUTY_COMMAND's limits (deputy_protocol.h), or its
// deputy would refuse the whole command: said here, at start, naming the process.
void CheckRemoteProcess(const ProcessSpec& p) {
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("process '" + p.name + "' on host '" + p.host + "': " + why);
  };
  if (p.name.size() > kMaxDeputyName || p.host.size() > kMaxDeputyName) fail("a name over 256 bytes");
  if (!(p.stop_timeout_s <= kMaxStopTimeoutS)) {
    fail("stop_timeout_s over " + std::to_string(static_cast<int>(kMaxStopTimeoutS)) + " s");
  }
  if (p.args.size() + 3 > kMaxArgc) fail("more than " + std::to_string(kMaxArgc - 3) + " arguments");
  if (p.command.size() > kMaxArgBytes) fail("a command over " + std::to_string(kMaxArgBytes) + " bytes");
  for (const std::string& arg : p.args) {
    if (arg.size() > kMaxArgBytes) fail("an argument over " + std::to_string(kMaxArgBytes) + " bytes");
  }
  if (p.env.size() + 3 > kMaxEnv) fail("more than " + std::to_string(kMaxEnv - 3) + " env variables");
  for (const auto& [key, value] : p.env) {
    if (key.size() > kMaxDeputyName || value.size() > kMaxArgBytes) fail("env " + key + " too long");
  }
}

}  // namespace

std::string RunFolderName(const std::string& log_dir) {
  if (log_dir.empty()) return "";
  std::error_code ec;
  std::filesystem::path path = std::filesystem::absolute(log_dir, ec).lexically_normal();
  if (!path.has_filename()) path = path.parent_path();  // "logs/run/"
  std::string name = path.filename().string();
  for (path = path.parent_path(); path.has_filename() && !ProvenanceRecordIn(path.string()).empty();
       path = path.parent_path()) {
    name = path.filename().string() + "." + name;
  }
  return RunDirOk(name) ? name : "";
}

Launcher::Launcher(const CommonFlags& flags, LaunchSpec spec, std::string bin_dir, std::string host,
                   std::string log_dir)
    : flags_(flags),
      spec_(std::move(spec)),
      bin_dir_(std::move(bin_dir)),
      host_(std::move(host)),
      log_dir_(std::move(log_dir)),
      process_(flags),
      deputies_(&process_, spec_.name + "@" + host_ + "/" + std::to_string(getpid()), NowMicros(),
                RunFolderName(log_dir_)) {
  name_width_ = 7;  // "process", the summary's header
  for (size_t g = 0; g < spec_.groups.size(); ++g) {
    for (const ProcessSpec& p : spec_.groups[g].processes) {
      name_width_ = std::max(name_width_, p.name.size());
    }
  }
  for (size_t g = 0; g < spec_.groups.size(); ++g) {
    for (const ProcessSpec& p : spec_.groups[g].processes) {
      Managed managed;
      managed.spec = p;
      managed.group = g;
      managed.remote = !p.host.empty() && p.host != host_;
      if (managed.remote) CheckRemoteProcess(p);
      managed.child = MakeChild(managed);
      managed.prefix = p.name + std::string(name_width_ - p.name.size(), ' ') + " | ";
      managed_.push_back(std::move(managed));
    }
  }
  std::map<std::string, size_t> per_host;
  for (const Managed& m : managed_) {
    if (m.remote && ++per_host[m.spec.host] > kMaxDeputyProcesses) {
      throw std::invalid_argument("more than " + std::to_string(kMaxDeputyProcesses) +
                                  " processes on host '" + m.spec.host +
                                  "' (one deputy runs at most that many)");
    }
  }
  process_.Subscribe<orbed::process_status_t>(
      channels::kProcessStatus, [this](const orbed::process_status_t& status, const std::string&,
                                       int64_t recv_utime) { OnHeartbeat(status, recv_utime); });
  process_.AddTimer(0.02, [this] { Tick(); });
}

std::unique_ptr<ChildHandle> Launcher::MakeChild(const Managed& m) {
  if (m.remote)
    return deputies_.MakeChild(m.spec.host, m.spec.name, m.spec.stop_signal, m.spec.stop_timeout_s);
  return std::make_unique<Child>();
}

Launcher::~Launcher() = default;

bool Launcher::StartProcess(Managed* m) {
  std::vector<std::string> argv = {m->spec.command};
  argv.insert(argv.end(), m->spec.args.begin(), m->spec.args.end());
  if (m->spec.ready == ReadyCheck::kHeartbeat &&
      std::find(m->spec.args.begin(), m->spec.args.end(), "--name") == m->spec.args.end()) {
    argv.push_back("--name");
    argv.push_back(m->spec.name);
  }
  std::map<std::string, std::string> env = m->spec.env;
  // Remote: the deputy expands ${ORBED_LOG_DIR} to its own run folder (else to this host's path).
  if (!m->remote || deputies_.run_dir().empty()) {
    for (std::string& arg : argv) arg = ExpandLogDir(arg, log_dir_);
    for (auto& [key, value] : env) value = ExpandLogDir(value, log_dir_);
  }
  env.emplace("ORBED_LCM_URL", flags_.lcm_url);
  env.emplace("ORBED_HOST", host_);
  env["ORBED_LOG_PREFIXED"] = "1";
  std::string error;
  m->child = MakeChild(*m);
  if (!m->child->Start(argv, env, bin_dir_, &error)) {
    m->last_exit = error;
    ORBED_LOG(kError) << m->spec.name << ": " << error;
    return false;
  }
  m->started = true;
  m->ready = m->spec.ready == ReadyCheck::kNone;
  m->finished = false;
  m->respawn_pending = false;
  m->started_at = Clock::now();
  if (m->remote) {
    ORBED_LOG(kInfo) << "asked deputy " << m->spec.host << " to start " << m->spec.name;
  } else {
    ORBED_LOG(kInfo) << "started " << m->spec.name << " (pid " << m->child->pid() << ")";
  }
  return true;
}

void Launcher::StartGroup(size_t group) {
  starting_group_ = group;
  group_started_at_ = Clock::now();
  ORBED_LOG(kInfo) << "starting group '" << spec_.groups[group].name << "'";
  for (Managed& m : managed_) {
    if (m.group != group) continue;
    if (!StartProcess(&m)) {
      if (m.spec.required) {
        FailTestbed("required process '" + m.spec.name + "' could not start: " + m.last_exit);
        return;
      }
      m.finished = true;
      m.ready = true;  // an optional process that cannot start does not hold up the launch
    }
  }
}

void Launcher::OnHeartbeat(const orbed::process_status_t& status, int64_t) {
  // A process saying it is stopping (e.g. the last heartbeat of a dying instance) is not ready.
  if (status.state != orbed::process_status_t::STATE_STARTING &&
      status.state != orbed::process_status_t::STATE_RUNNING) {
    return;
  }
  for (Managed& m : managed_) {
    if (m.spec.name != status.name || !m.child->running() || m.ready) continue;
    // A heartbeat still on its way from an instance that died is not the new instance's.
    if (status.pid > 0 && status.pid != m.child->pid()) continue;
    if (m.remote && status.host != m.spec.host) continue;
    m.ready = true;
    if (m.restarts == 0) {
      ORBED_LOG(kInfo) << m.spec.name << " is ready (first heartbeat after " << SecondsSince(m.started_at)
                       << " s)";
    } else {
      ORBED_LOG(kInfo) << m.spec.name << " is ready again (" << SecondsSince(m.unready_since)
                       << " s after it died; restart " << m.restarts << ")";
    }
  }
}

void Launcher::HandleExit(Managed* m) {
  m->child->Drain(m->prefix, true);
  m->last_exit = m->child->DescribeExit();
  const bool success = m->child->exit_code() == 0 && m->child->term_signal() == 0;
  if (stopping_) return;
  if (m->spec.exit_stops_all) {
    if (m->child->term_signal() != 0) {
      ORBED_LOG(kError) << m->spec.name << " " << m->last_exit << " before it finished: stopping the testbed";
    } else {
      ORBED_LOG(kInfo) << m->spec.name << " " << m->last_exit << ": stopping the testbed";
    }
    m->finished = true;
    if (!success && exit_code_ == 0) exit_code_ = m->child->exit_code() > 0 ? m->child->exit_code() : 1;
    process_.RequestStop();
    return;
  }
  if (m->child->exit_code() == kExitCannotWrite) {
    // It cannot write its output (a full disk): not a crash, and a new instance would fail the
    // same way, so it is not respawned.
    m->finished = true;
    const std::string said = m->child->last_line();
    const std::string reason = "process '" + m->spec.name + "' " + m->last_exit +
                               ": it cannot write its output, not respawned" +
                               (said.empty() ? "" : " (it said: " + EscapeText(said) + ")");
    if (m->spec.required) {
      FailTestbed("required " + reason);
    } else {
      ORBED_LOG(kWarn) << "optional " << reason << "; continuing without it";
    }
    return;
  }
  if (m->spec.respawn) {
    if (m->ready) m->unready_since = Clock::now();
    const bool fast = SecondsSince(m->started_at) < 1.0;
    m->fast_failures = fast ? m->fast_failures + 1 : 0;
    // Immediately the first time; 0.25, 0.5, ... up to 5 s while it keeps dying at once.
    const double delay =
        m->fast_failures <= 1 ? 0.0 : std::min(5.0, 0.25 * (1 << std::min(m->fast_failures - 2, 5)));
    ORBED_LOG(kWarn) << m->spec.name << " " << m->last_exit << "; respawning"
                     << (delay > 0 ? " in " + std::to_string(delay) + " s" : "");
    m->respawn_pending = true;
    m->respawn_at =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(delay));
    return;
  }
  m->finished = true;
  if (m->spec.required && !success) {
    FailTestbed("required process '" + m->spec.name + "' " + m->last_exit);
  } else if (m->spec.required && !m->ready) {
    FailTestbed("required process '" + m->spec.name + "' " + m->last_exit + " before its first heartbeat");
  } else if (!success) {
    ORBED_LOG(kWarn) << "optional process " << m->spec.name << " " << m->last_exit
                     << "; continuing without it";
  } else {
    ORBED_LOG(kInfo) << m->spec.name << " finished (exit code 0)";
  }
}

void Launcher::FailTestbed(const std::string& reason) {
  ORBED_LOG(kError) << reason;
  process_.SetLastError(reason);
  exit_code_ = 1;
  process_.RequestStop();
}

void Launcher::Tick() {
  deputies_.Tick();
  if (!stopping_ && exit_code_ == 0) {
    const std::string lost = deputies_.LostDeputy();
    if (!lost.empty()) {
      FailTestbed("deputy " + lost +
                  " stopped following this launch (it heard nothing from it for its --orphan-timeout-s, or a "
                  "later launch took it over) and stopped its processes");
      return;
    }
  }
  for (Managed& m : managed_) {
    if (!m.started) continue;
    m.child->Drain(m.prefix);
    if (m.child->running() && m.child->Poll()) HandleExit(&m);
    if (m.respawn_pending && !stopping_ && Clock::now() >= m.respawn_at) {
      ++m.restarts;
      if (!StartProcess(&m)) {
        m.respawn_pending = true;
        m.respawn_at = Clock::now() + std::chrono::seconds(1);
      }
    }
  }
  if (stopping_ || exit_code_ != 0) return;
  // Readiness of respawned processes in the groups already up.
  for (const Managed& m : managed_) {
    if (m.restarts == 0 || m.ready || !m.spec.required || (!all_started_ && m.group >= starting_group_))
      continue;
    if (SecondsSince(m.unready_since) > m.spec.ready_timeout_s) {
      FailTestbed("process '" + m.spec.name + "' was respawned " + std::to_string(m.restarts) +
                  " time(s) and sent no heartbeat within " + std::to_string(m.spec.ready_timeout_s) +
                  " s of dying (" + m.last_exit + ")");
      return;
    }
  }
  if (all_started_) return;
  // Readiness of the group being started.
  bool group_ready = true;
  for (Managed& m : managed_) {
    if (m.group != starting_group_ || m.ready) continue;
    if (m.finished && !m.spec.required) continue;  // an optional process that is gone already
    group_ready = false;
    // Measured from the group's start, not the last respawn: a child that keeps dying before
    // its first heartbeat must still time out.
    if (SecondsSince(group_started_at_) > m.spec.ready_timeout_s) {
      if (m.remote && !deputies_.Heard(m.spec.host)) {
        FailTestbed("process '" + m.spec.name + "' is placed on host '" + m.spec.host +
                    "', whose deputy was not heard on DEPUTY_STATUS within " +
                    std::to_string(m.spec.ready_timeout_s) + " s: start `orbed-launch --deputy " +
                    m.spec.host + "` on that host, on this LCM URL (" + flags_.lcm_url + ")");
        return;
      }
      FailTestbed("process '" + m.spec.name + "' sent no heartbeat on PROCESS_STATUS within " +
                  std::to_string(m.spec.ready_timeout_s) +
                  " s (if it is not an orbed process, set `ready: none` in " + spec_.path + ")");
      return;
    }
  }
  if (!group_ready) return;
  ORBED_LOG(kInfo) << "group '" << spec_.groups[starting_group_].name << "' ready after "
                   << SecondsSince(group_started_at_) << " s";
  if (starting_group_ + 1 < spec_.groups.size()) {
    StartGroup(starting_group_ + 1);
  } else {
    all_started_ = true;
    ORBED_LOG(kInfo) << "testbed '" << spec_.name << "' is up (" << SecondsSince(launch_started_at_) << " s)";
  }
}

void Launcher::StopEverything() {
  stopping_ = true;
  for (size_t g = spec_.groups.size(); g-- > 0;) {
    std::vector<Managed*> group;
    for (Managed& m : managed_) {
      m.respawn_pending = false;
      if (m.group == g && m.started && m.child->running()) group.push_back(&m);
    }
    if (group.empty()) continue;
    ORBED_LOG(kInfo) << "stopping group '" << spec_.groups[g].name << "'";
    double timeout = 0;
    for (Managed* m : group) {
      m->child->Signal(m->spec.stop_signal);
      timeout = std::max(timeout, m->spec.stop_timeout_s);
    }
    deputies_.Tick();  // the remote stops go out now
    // A deputy not heard lately cannot confirm a stop: its processes are left to its orphan timeout.
    for (auto it = group.begin(); it != group.end();) {
      Managed* m = *it;
      if (m->remote && !deputies_.Reachable(m->spec.host)) {
        ORBED_LOG(kWarn) << "deputy " << m->spec.host << " is not reachable: cannot confirm that "
                         << m->spec.name << " stops (its deputy stops it after its orphan timeout)";
        m->last_exit = "not confirmed stopped: deputy " + m->spec.host + " not reachable";
        it = group.erase(it);
      } else {
        ++it;
      }
    }
    const auto begin = Clock::now();
    bool killed = false;
    for (;;) {
      bool any_running = false;
      for (Managed* m : group) {
        m->child->Drain(m->prefix);
        if (m->child->running() && !m->child->Poll()) any_running = true;
        if (!m->child->running()) m->last_exit = m->child->DescribeExit();
      }
      if (!any_running) break;
      if (killed && SecondsSince(begin) > timeout + kRemoteStopGraceS) {
        for (Managed* m : group) {
          if (m->child->running()) {
            ORBED_LOG(kWarn) << "deputy " << m->spec.host << " did not confirm that " << m->spec.name
                             << " stopped; leaving it to the deputy's orphan timeout";
            m->last_exit = "not confirmed stopped by deputy " + m->spec.host;
          }
        }
        break;
      }
      if (!killed && SecondsSince(begin) > timeout) {
        for (Managed* m : group) {
          if (m->child->running()) {
            ORBED_LOG(kWarn) << m->spec.name << " did not stop within " << m->spec.stop_timeout_s
                             << " s: SIGKILL";
            m->child->Signal(SIGKILL);
          }
        }
        killed = true;
      }
      // Waits up to 10 ms for the deputies' statuses (and sends them the stops).
      deputies_.Tick();
      process_.lcm().handleTimeout(10);
    }
    for (Managed* m : group) {
      m->child->Drain(m->prefix, true);
      // Stopped by its own stop signal (or our SIGKILL) is a normal end; an exit code other than
      // 0 from a required process is a failure (e.g. the logger could not write its log).
      if (m->spec.required && m->child->exit_code() > 0 && exit_code_ == 0) {
        ORBED_LOG(kError) << "required process '" << m->spec.name << "' " << m->last_exit
                          << " while stopping";
        exit_code_ = 1;
      }
    }
  }
}

void Launcher::PrintSummary() const {
  std::fprintf(stdout, "\norbed-launch summary (%s):\n", spec_.name.c_str());
  std::fprintf(stdout, "  %-*s  %-8s  %s\n", static_cast<int>(name_width_), "process", "restarts",
               "last state");
  for (const Managed& m : managed_) {
    std::fprintf(stdout, "  %-*s  %-8d  %s\n", static_cast<int>(name_width_), m.spec.name.c_str(), m.restarts,
                 m.started ? m.last_exit.c_str() : "not started");
  }
  std::fflush(stdout);
}

int Launcher::Run() {
  launch_started_at_ = Clock::now();
  ORBED_LOG(kInfo) << "launching '" << spec_.name << "' from " << spec_.path << " on " << flags_.lcm_url;
  StartGroup(0);
  process_.Run();
  StopEverything();
  deputies_.SayGoodbye();
  PrintSummary();
  if (exit_code_ != 0) ORBED_LOG(kError) << "testbed failed: exit code " << exit_code_;
  return exit_code_;
}

}  // namespace orbed::launcher
