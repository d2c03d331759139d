#include "procs/launcher/deputy.h"

#include <csignal>
#include <filesystem>
#include <thread>

#include "base/log.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/launcher/deputy_protocol.h"

namespace orbed::launcher {
namespace {

constexpr double kUnlistedStopTimeoutS = 5.0;

double SecondsSince(Deputy::Clock::time_point t) {
  return std::chrono::duration<double>(Deputy::Clock::now() - t).count();
}

// Keeps the last kMaxLastLines lines, each cut to kMaxLastLineBytes.
void KeepLastLines(std::vector<std::string>* lines) {
  if (lines->size() > kMaxLastLines) lines->erase(lines->begin(), lines->end() - kMaxLastLines);
  for (std::string& line : *lines) {
    if (line.size() > kMaxLastLineBytes) line.resize(kMaxLastLineBytes);
  }
}

}  // namespace

Deputy::Deputy(const CommonFlags& flags, DeputyOptions options)
    : options_(std::move(options)), flags_(flags), process_(flags) {
  process_.Subscribe<orbed::deputy_command_t>(
      channels::kDeputyCommand,
      [this](const orbed::deputy_command_t& command, const std::string&, int64_t) { OnCommand(command); });
  process_.AddWallPoll(0.02, [this] { Tick(); });
  last_status_ = Clock::now();
}

Deputy::~Deputy() = default;

void Deputy::Start(Managed* m, const orbed::deputy_process_t& wanted) {
  std::vector<std::string> argv = wanted.argv;
  std::map<std::string, std::string> env;
  for (size_t i = 0; i < wanted.env_key.size(); ++i) env[wanted.env_key[i]] = wanted.env_value[i];
  std::string error;
  if (!run_dir_.empty()) {
    // This host's folder of the run, wherever the launcher keeps its own.
    const std::filesystem::path dir = std::filesystem::absolute(options_.log_root) / run_dir_;
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) error = "cannot make its run folder " + dir.string() + ": " + ec.message();
    for (std::string& arg : argv) arg = ExpandLogDir(arg, dir.string());
    for (auto& [key, value] : env) value = ExpandLogDir(value, dir.string());
    env["ORBED_LOG_DIR"] = dir.string();
  }
  env["ORBED_LCM_URL"] = flags_.lcm_url;
  env["ORBED_HOST"] = options_.name;
  env["ORBED_LOG_PREFIXED"] = "1";
  m->name = wanted.name;
  m->instance = wanted.instance;
  m->stop_signal = wanted.stop_signal;
  m->stop_timeout_s = wanted.stop_timeout_s;
  m->signal_sent = 0;
  m->prefix = wanted.name + " | ";
  m->child = std::make_unique<Child>();
  m->last_lines = std::make_unique<std::vector<std::string>>();
  m->child->CopyLinesTo(m->last_lines.get());
  m->failed_to_start = !error.empty() || !m->child->Start(argv, env, options_.bin_dir, &error);
  m->detail = m->failed_to_start ? error : "running";
  if (m->failed_to_start) {
    ORBED_LOG(kError) << wanted.name << " (instance " << wanted.instance << "): " << error;
  } else {
    ORBED_LOG(kInfo) << "started " << wanted.name << " (instance " << wanted.instance << ", pid "
                     << m->child->pid() << ") for " << launcher_;
  }
  changed_ = true;
}

void Deputy::Stop(Managed* m, int signal, double timeout_s) {
  // Once SIGKILL went out there is nothing stronger (nor weaker) to send.
  if (!m->child || !m->child->running() || m->signal_sent == signal || m->signal_sent == SIGKILL) return;
  if (m->signal_sent == 0) {
    m->kill_at =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  }
  m->child->Signal(signal);
  m->signal_sent = signal;
  m->detail = "stopping";
  changed_ = true;
}

void Deputy::StopAll(std::vector<Managed>* list, const char* why) {
  for (Managed& m : *list) {
    if (m.child && m.child->running() && m.signal_sent == 0) {
      ORBED_LOG(kInfo) << "stopping " << m.name << ": " << why;
      Stop(&m, m.stop_signal, m.stop_timeout_s);
    }
  }
}

Deputy::Managed* Deputy::Replace(Managed* current) {
  if (current == nullptr) {
    children_.emplace_back();
    return &children_.back();
  }
  Stop(current, SIGKILL, 0);
  leaving_.push_back(std::move(*current));
  *current = Managed{};
  return current;
}

void Deputy::Forget(const char* why) {
  StopAll(&children_, why);
  for (Managed& m : children_) {
    if (m.child && m.child->running()) leaving_.push_back(std::move(m));
  }
  children_.clear();
  launcher_.clear();  // launcher_start_utime_ stays: only a later launcher is followed next
  changed_ = true;
}

void Deputy::OnCommand(const orbed::deputy_command_t& command) {
  const std::string problem = CheckDeputyCommand(command);
  if (!problem.empty()) {
    process_.Reject(std::string(channels::kDeputyCommand) + "/invalid", problem);
    return;
  }
  if (command.deputy != options_.name) return;  // another deputy's
  if (command.launcher != launcher_) {
    if (command.processes.empty()) return;  // a goodbye from a launcher not followed (any more)
    // Only a launcher that started later replaces the one followed: an earlier one's datagrams
    // (late, or from a launch left running) must not make the two take turns.
    // (Also after a launcher was forgotten: its late datagrams do not bring it back.)
    if (command.launcher_start_utime <= launcher_start_utime_) {
      if (ignored_launchers_.size() < 16 && ignored_launchers_.insert(command.launcher).second) {
        ORBED_LOG(kWarn) << "ignoring " << command.launcher
                         << ", which started no later than the last launcher "
                         << "followed" << (launcher_.empty() ? "" : " (" + launcher_ + ")");
      }
      return;
    }
    if (!launcher_.empty()) {
      ORBED_LOG(kWarn) << "now following " << command.launcher << " (was " << launcher_ << ")";
      Forget("its launcher was replaced");
    } else {
      ORBED_LOG(kInfo) << "following " << command.launcher;
    }
    launcher_ = command.launcher;
    launcher_start_utime_ = command.launcher_start_utime;
    changed_ = true;
  }
  last_command_ = Clock::now();
  run_dir_ = command.run_dir;
  if (command.processes.empty()) {
    // The launcher's goodbye: whatever still runs stops, and the next launcher is welcome.
    ORBED_LOG(kInfo) << launcher_ << " is done";
    Forget("its launcher is done");
    return;
  }
  for (const orbed::deputy_process_t& wanted : command.processes) {
    Managed* current = nullptr;
    for (Managed& m : children_) {
      if (m.name == wanted.name) current = &m;
    }
    if (wanted.run) {
      if (current != nullptr && current->instance >= wanted.instance) continue;
      // An earlier launcher's process of that name still stopping: start once it is gone (the
      // command comes again in 0.2 s), never two at once.
      bool predecessor_running = false;
      for (const Managed& m : leaving_) {
        predecessor_running = predecessor_running || (m.name == wanted.name && m.child && m.child->running());
      }
      if (predecessor_running) continue;
      // A newer instance while the old one runs (the launcher missed its exit): the old one goes.
      current = Replace(current);
      Start(current, wanted);
    } else if (current != nullptr && current->instance == wanted.instance) {
      Stop(current, wanted.stop_signal, wanted.stop_timeout_s);
    } else if (current == nullptr || current->instance < wanted.instance) {
      // Stopped before it started here (the start was lost, or overtaken): it is reported as
      // exited, so the launcher's stop completes; an older instance still running goes too.
      current = Replace(current);
      current->name = wanted.name;
      current->instance = wanted.instance;
      current->detail = "stopped before it started";
      changed_ = true;
    }
  }
  // Processes the launcher no longer lists.
  for (auto it = children_.begin(); it != children_.end();) {
    bool listed = false;
    for (const orbed::deputy_process_t& wanted : command.processes)
      listed = listed || wanted.name == it->name;
    if (listed) {
      ++it;
      continue;
    }
    Stop(&*it, SIGTERM, kUnlistedStopTimeoutS);
    leaving_.push_back(std::move(*it));
    it = children_.erase(it);
    changed_ = true;
  }
}

bool Deputy::AnyRunning() const {
  for (const auto* list : {&children_, &leaving_}) {
    for (const Managed& m : *list) {
      if (m.child && m.child->running()) return true;
    }
  }
  return false;
}

void Deputy::Tick() {
  for (auto* list : {&children_, &leaving_}) {
    for (Managed& m : *list) {
      if (!m.child) continue;
      m.child->Drain(m.prefix);
      if (m.child->running() && m.child->Poll()) {
        m.child->Drain(m.prefix, true);
        KeepLastLines(m.last_lines.get());
        m.detail = m.child->DescribeExit();
        if (m.signal_sent != 0 || m.child->exit_code() == 0) {
          ORBED_LOG(kInfo) << m.name << " (instance " << m.instance << ") " << m.detail;
        } else {
          ORBED_LOG(kWarn) << m.name << " (instance " << m.instance << ") " << m.detail;
        }
        changed_ = true;
      }
      KeepLastLines(m.last_lines.get());
      if (m.child->running() && m.signal_sent != 0 && m.signal_sent != SIGKILL && Clock::now() >= m.kill_at) {
        ORBED_LOG(kWarn) << m.name << " did not stop within " << m.stop_timeout_s << " s: SIGKILL";
        m.child->Signal(SIGKILL);
        m.signal_sent = SIGKILL;
      }
    }
  }
  // Forget what has left.
  for (auto it = leaving_.begin(); it != leaving_.end();) {
    it = (it->child && it->child->running()) ? it + 1 : leaving_.erase(it);
  }
  if (!launcher_.empty() && SecondsSince(last_command_) > options_.orphan_timeout_s) {
    ORBED_LOG(kWarn) << "no command from " << launcher_ << " for " << SecondsSince(last_command_)
                     << " s: stopping what it started and forgetting it";
    Forget("its launcher is gone");
  }
  if (changed_ || SecondsSince(last_status_) >= kDeputyPeriodS) {
    process_.PublishControl(channels::kDeputyStatus, Status());
    last_status_ = Clock::now();
    changed_ = false;
  }
}

orbed::deputy_status_t Deputy::Status() const {
  orbed::deputy_status_t status{};
  status.utime = NowMicros();
  status.deputy = options_.name;
  status.launcher = launcher_;
  for (const Managed& m : children_) {
    orbed::deputy_child_t c{};
    c.name = m.name;
    c.instance = m.instance;
    c.pid = m.child && !m.failed_to_start ? static_cast<int32_t>(m.child->pid()) : 0;
    if (!m.child) {  // stopped before it started
      c.state = orbed::deputy_child_t::STATE_EXITED;
    } else if (m.failed_to_start) {
      c.state = orbed::deputy_child_t::STATE_FAILED_TO_START;
      c.exit_code = 127;
    } else if (m.child->running()) {
      c.state =
          m.signal_sent != 0 ? orbed::deputy_child_t::STATE_STOPPING : orbed::deputy_child_t::STATE_RUNNING;
    } else {
      c.state = orbed::deputy_child_t::STATE_EXITED;
      c.exit_code = m.child->exit_code();
      c.term_signal = m.child->term_signal();
      // Why it ended, in its own words (only exited children's: the status stays small).
      c.last_lines = *m.last_lines;
    }
    c.num_last_lines = static_cast<int32_t>(c.last_lines.size());
    c.detail = m.detail;
    status.children.push_back(std::move(c));
  }
  status.num_children = static_cast<int32_t>(status.children.size());
  return status;
}

int Deputy::Run() {
  ORBED_LOG(kInfo) << "deputy " << options_.name << " on " << flags_.lcm_url << " (orphan timeout "
                   << options_.orphan_timeout_s << " s)";
  process_.Run();
  // Stop what runs, as the launcher would: stop signal, then SIGKILL.
  StopAll(&children_, "the deputy is stopping");
  while (AnyRunning()) {
    Tick();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return 0;
}

}  // namespace orbed::launcher
