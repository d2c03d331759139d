#include "procs/launcher/launch_plan.h"

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "base/format.h"
#include "base/run_folder.h"
#include "procs/launcher/deputy_protocol.h"
#include "runtime/process.h"

namespace orbed::launcher {
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

LaunchPlan::LaunchPlan(LaunchSpec spec, std::string host) : spec_(std::move(spec)), host_(std::move(host)) {
  for (const GroupSpec& group : spec_.groups) {
    for (const ProcessSpec& p : group.processes) name_width_ = std::max(name_width_, p.name.size());
  }
  std::map<std::string, size_t> per_host;
  for (size_t g = 0; g < spec_.groups.size(); ++g) {
    for (const ProcessSpec& p : spec_.groups[g].processes) {
      Entry e;
      e.spec = p;
      e.group = g;
      e.remote = !p.host.empty() && p.host != host_;
      if (e.remote) CheckRemoteProcess(p);
      e.prefix = p.name + std::string(name_width_ - p.name.size(), ' ') + " | ";
      entries_.push_back(std::move(e));
    }
  }
  for (const Entry& e : entries_) {
    if (e.remote && ++per_host[e.spec.host] > kMaxDeputyProcesses) {
      throw std::invalid_argument("more than " + std::to_string(kMaxDeputyProcesses) +
                                  " processes on host '" + e.spec.host +
                                  "' (one deputy runs at most that many)");
    }
  }
}

ChildCommand LaunchPlan::Command(const Entry& e, bool expand_log_dir, const std::string& log_dir,
                                 const std::string& lcm_url) const {
  ChildCommand c;
  c.argv = {e.spec.command};
  c.argv.insert(c.argv.end(), e.spec.args.begin(), e.spec.args.end());
  if (e.spec.ready == ReadyCheck::kHeartbeat &&
      std::find(e.spec.args.begin(), e.spec.args.end(), "--name") == e.spec.args.end()) {
    c.argv.push_back("--name");
    c.argv.push_back(e.spec.name);
  }
  c.env = e.spec.env;
  if (expand_log_dir) {
    for (std::string& arg : c.argv) arg = ExpandLogDir(arg, log_dir);
    for (auto& [key, value] : c.env) value = ExpandLogDir(value, log_dir);
  }
  c.env.emplace("ORBED_LCM_URL", lcm_url);
  c.env.emplace("ORBED_HOST", host_);
  c.env["ORBED_LOG_PREFIXED"] = "1";
  return c;
}

void LaunchPlan::BeginGroup(size_t group, double now_s) {
  starting_group_ = group;
  group_started_at_s_ = now_s;
}

void LaunchPlan::Started(Entry* e, double now_s) {
  e->started = true;
  e->ready = e->spec.ready == ReadyCheck::kNone;
  e->finished = false;
  e->respawn_pending = false;
  e->started_at_s = now_s;
}

std::string LaunchPlan::CouldNotStart(Entry* e) {
  if (e->spec.required) return "required process '" + e->spec.name + "' could not start: " + e->last_exit;
  e->finished = true;
  e->ready = true;  // an optional process that cannot start does not hold up the launch
  return "";
}

std::vector<Note> LaunchPlan::OnHeartbeat(const std::string& name, int64_t pid, const std::string& host,
                                          const std::function<bool(size_t)>& running,
                                          const std::function<int64_t(size_t)>& pid_of, double now_s) {
  std::vector<Note> notes;
  for (size_t i = 0; i < entries_.size(); ++i) {
    Entry& e = entries_[i];
    if (e.spec.name != name || !running(i) || e.ready) continue;
    // A heartbeat still on its way from an instance that died is not the new instance's.
    if (pid > 0 && pid != pid_of(i)) continue;
    if (e.remote && host != e.spec.host) continue;
    e.ready = true;
    std::ostringstream text;
    if (e.restarts == 0) {
      text << e.spec.name << " is ready (first heartbeat after " << now_s - e.started_at_s << " s)";
    } else {
      text << e.spec.name << " is ready again (" << now_s - e.unready_since_s << " s after it died; restart "
           << e.restarts << ")";
    }
    notes.push_back({LogLevel::kInfo, text.str()});
  }
  return notes;
}

LaunchPlan::ExitVerdict LaunchPlan::OnExit(Entry* e, int exit_code, int term_signal,
                                           const std::string& description, const std::string& last_line,
                                           double now_s) {
  using Action = ExitVerdict::Action;
  e->last_exit = description;
  const bool success = exit_code == 0 && term_signal == 0;
  if (stopping_) return {};
  const std::string& name = e->spec.name;
  if (e->spec.exit_stops_all) {
    e->finished = true;
    if (!success && exit_code_ == 0) exit_code_ = exit_code > 0 ? exit_code : 1;
    if (term_signal != 0) {
      return {Action::kStopAll,
              {LogLevel::kError, name + " " + description + " before it finished: stopping the testbed"}};
    }
    return {Action::kStopAll, {LogLevel::kInfo, name + " " + description + ": stopping the testbed"}};
  }
  if (exit_code == kExitCannotWrite) {
    // It cannot write its output (a full disk): not a crash, and a new instance would fail the
    // same way, so it is not respawned.
    e->finished = true;
    const std::string reason = "process '" + name + "' " + description +
                               ": it cannot write its output, not respawned" +
                               (last_line.empty() ? "" : " (it said: " + EscapeText(last_line) + ")");
    if (e->spec.required) return {Action::kFail, {LogLevel::kError, "required " + reason}};
    return {Action::kNone, {LogLevel::kWarn, "optional " + reason + "; continuing without it"}};
  }
  if (e->spec.respawn) {
    if (e->ready) e->unready_since_s = now_s;
    const bool fast = now_s - e->started_at_s < 1.0;
    e->fast_failures = fast ? e->fast_failures + 1 : 0;
    // Immediately the first time; 0.25, 0.5, ... up to 5 s while it keeps dying at once.
    const double delay =
        e->fast_failures <= 1 ? 0.0 : std::min(5.0, 0.25 * (1 << std::min(e->fast_failures - 2, 5)));
    e->respawn_pending = true;
    e->respawn_at_s = now_s + delay;
    return {Action::kNone,
            {LogLevel::kWarn, name + " " + description + "; respawning" +
                                  (delay > 0 ? " in " + std::to_string(delay) + " s" : "")}};
  }
  e->finished = true;
  if (e->spec.required && !success)
    return {Action::kFail, {LogLevel::kError, "required process '" + name + "' " + description}};
  if (e->spec.required && !e->ready) {
    return {
        Action::kFail,
        {LogLevel::kError, "required process '" + name + "' " + description + " before its first heartbeat"}};
  }
  if (!success) {
    return {Action::kNone,
            {LogLevel::kWarn, "optional process " + name + " " + description + "; continuing without it"}};
  }
  return {Action::kNone, {LogLevel::kInfo, name + " finished (exit code 0)"}};
}

void LaunchPlan::RespawnFailed(Entry* e, double now_s) {
  e->respawn_pending = true;
  e->respawn_at_s = now_s + 1.0;
}

std::string LaunchPlan::RespawnTimeout(double now_s) const {
  for (const Entry& e : entries_) {
    if (e.restarts == 0 || e.ready || !e.spec.required || (!all_started_ && e.group >= starting_group_))
      continue;
    if (now_s - e.unready_since_s > e.spec.ready_timeout_s) {
      return "process '" + e.spec.name + "' was respawned " + std::to_string(e.restarts) +
             " time(s) and sent no heartbeat within " + std::to_string(e.spec.ready_timeout_s) +
             " s of dying (" + e.last_exit + ")";
    }
  }
  return "";
}

LaunchPlan::GroupCheck LaunchPlan::CheckGroup(double now_s,
                                              const std::function<bool(const std::string&)>& heard,
                                              const std::string& lcm_url) const {
  GroupCheck check;
  check.ready = true;
  for (const Entry& e : entries_) {
    if (e.group != starting_group_ || e.ready) continue;
    if (e.finished && !e.spec.required) continue;  // an optional process that is gone already
    check.ready = false;
    // Measured from the group's start, not the last respawn: a child that keeps dying before
    // its first heartbeat must still time out.
    if (now_s - group_started_at_s_ <= e.spec.ready_timeout_s) continue;
    if (e.remote && !heard(e.spec.host)) {
      check.failure = "process '" + e.spec.name + "' is placed on host '" + e.spec.host +
                      "', whose deputy was not heard on DEPUTY_STATUS within " +
                      std::to_string(e.spec.ready_timeout_s) + " s: start `orbed-launch --deputy " +
                      e.spec.host + "` on that host, on this LCM URL (" + lcm_url + ")";
    } else {
      check.failure = "process '" + e.spec.name + "' sent no heartbeat on PROCESS_STATUS within " +
                      std::to_string(e.spec.ready_timeout_s) +
                      " s (if it is not an orbed process, set `ready: none` in " + spec_.path + ")";
    }
    return check;
  }
  return check;
}

bool LaunchPlan::NextGroup() {
  if (starting_group_ + 1 < spec_.groups.size()) return true;
  all_started_ = true;
  return false;
}

void LaunchPlan::BeginStop() {
  stopping_ = true;
  for (Entry& e : entries_) e.respawn_pending = false;
}

Note LaunchPlan::StoppedWith(const Entry& e, int exit_code) {
  // Stopped by its own stop signal (or our SIGKILL) is a normal end; an exit code other than 0
  // from a required process is a failure (e.g. the logger could not write its log).
  if (!e.spec.required || exit_code <= 0 || exit_code_ != 0) return {};
  exit_code_ = 1;
  return {LogLevel::kError, "required process '" + e.spec.name + "' " + e.last_exit + " while stopping"};
}

std::string LaunchPlan::Summary() const {
  // Columns as printf's "  %-*s  %-8s  %s": the names padded to the longest.
  const auto pad = [](const std::string& s, size_t width) {
    return s.size() >= width ? s : s + std::string(width - s.size(), ' ');
  };
  std::string out = "\norbed-launch summary (" + spec_.name + "):\n";
  out += "  " + pad("process", name_width_) + "  " + pad("restarts", 8) + "  last state\n";
  for (const Entry& e : entries_) {
    out += "  " + pad(e.spec.name, name_width_) + "  " + pad(std::to_string(e.restarts), 8) + "  " +
           (e.started ? e.last_exit : "not started") + "\n";
  }
  return out;
}

}  // namespace orbed::launcher
