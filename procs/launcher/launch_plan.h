#pragma once
/// @file
/// orbed-launch's core (the process is launcher.h, its shell): the launch plan's decisions without
/// children, a bus or a clock. The shell starts, polls, signals and stops the children (child.h,
/// deputy_link.h) and hands this the facts (a child started, exited, sent a heartbeat) and the time;
/// it answers what to do: respawn when, fail the testbed why, start the next group, what to log.
///
///   Placement: a process on another host must fit DEPUTY_COMMAND's limits (deputy_protocol.h) and
///     at most kMaxDeputyProcesses run on one host (std::invalid_argument naming the process/host).
///   Command: argv = command, args, then "--name <name>" for heartbeat-ready processes without
///     --name; env = the spec's, ${ORBED_LOG_DIR} expanded unless the deputy does it, plus
///     ORBED_LCM_URL, ORBED_HOST (unless the spec sets them) and ORBED_LOG_PREFIXED=1.
///   Readiness: a heartbeat STARTING or RUNNING from the running instance's pid (and, remote, its
///     host) makes a process ready; `ready: none` is ready when started. The group being started
///     is ready when every process is ready or (optional) gone; one not ready ready_timeout_s after
///     the group's start fails the testbed (naming its deputy when that was never heard). A
///     respawned required process not ready again ready_timeout_s after it died fails it.
///   Exits (not while stopping): exit_stops_all stops the testbed (its exit code the launcher's
///     when it failed); kExitCannotWrite is never respawned (a required one fails the testbed with
///     its last line); `respawn` restarts at once, then after 0.25, 0.5, ... 5 s while it keeps
///     dying within 1 s of starting; otherwise a failed, or never ready, required process fails it.
///     A respawn that cannot start is tried again 1 s later.
///   Stopping: groups in reverse order; a required process that exits with a code > 0 fails it.
///
/// Time: now_s is any monotonic clock [s]. Threading: not synchronised; one thread.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "base/log.h"
#include "procs/launcher/launch_file.h"

namespace orbed::launcher {

/// The run folder's name, as deputies make it under their logs folders (deputy_command_t.run_dir):
/// `log_dir`'s own name after those of the run folders it is in (folders holding a provenance
/// record, base/run_folder.h), joined by '.': "study-<time>-<random>.setup-u1" for a study's user,
/// whose own name repeats in every study, so that it is as unique on every host as on this one;
/// "" when it has none that RunDirOk accepts.
std::string RunFolderName(const std::string& log_dir);

/// Something to log; empty text: nothing.
struct Note {
  LogLevel level{LogLevel::kInfo};
  std::string text;
};

struct ChildCommand {
  std::vector<std::string> argv;
  std::map<std::string, std::string> env;
};

class LaunchPlan {
 public:
  /// One process of the plan and what the launcher knows of it.
  struct Entry {
    ProcessSpec spec;
    size_t group = 0;
    bool remote = false;
    std::string prefix;  // "<name padded> | ", its output lines' prefix
    bool started = false;
    bool ready = false;
    bool finished = false;  // exited and will not be restarted
    int restarts = 0;
    int fast_failures = 0;  // consecutive deaths within 1 s of starting
    double started_at_s = 0;
    double unready_since_s = 0;  // when it died after its last readiness (respawns)
    double respawn_at_s = 0;
    bool respawn_pending = false;
    std::string last_exit;
  };

  /// `host`: this host's name (processes without `host:` or with this one run here).
  LaunchPlan(LaunchSpec spec, std::string host);

  const LaunchSpec& spec() const { return spec_; }
  std::vector<Entry>& entries() { return entries_; }
  const std::vector<Entry>& entries() const { return entries_; }
  /// The launcher's exit code so far (0, 1, or an exit_stops_all process's).
  int exit_code() const { return exit_code_; }
  bool stopping() const { return stopping_; }
  size_t starting_group() const { return starting_group_; }
  bool all_started() const { return all_started_; }
  double group_started_at_s() const { return group_started_at_s_; }

  /// The child's argv and env; `expand_log_dir`: ${ORBED_LOG_DIR} becomes log_dir here.
  ChildCommand Command(const Entry& e, bool expand_log_dir, const std::string& log_dir,
                       const std::string& lcm_url) const;
  /// The group starts at now_s.
  void BeginGroup(size_t group, double now_s);
  /// The entry's child started at now_s.
  void Started(Entry* e, double now_s);
  /// The entry's child could not start (StartGroup): the testbed's failure for a required one, else
  /// "" (it is gone and does not hold up the launch).
  std::string CouldNotStart(Entry* e);
  /// A heartbeat STARTING or RUNNING of `name` from `pid` on `host`, the children's states given by
  /// `running` and `pid_of` (index into entries()): the notes of the processes it makes ready.
  std::vector<Note> OnHeartbeat(const std::string& name, int64_t pid, const std::string& host,
                                const std::function<bool(size_t)>& running,
                                const std::function<int64_t(size_t)>& pid_of, double now_s);
  struct ExitVerdict {
    enum class Action { kNone, kStopAll, kFail } action = Action::kNone;
    Note note;  // with kFail: the reason
  };
  /// The entry's child exited (code, signal, DescribeExit, its last output line) at now_s.
  ExitVerdict OnExit(Entry* e, int exit_code, int term_signal, const std::string& description,
                     const std::string& last_line, double now_s);
  bool RespawnDue(const Entry& e, double now_s) const {
    return e.respawn_pending && !stopping_ && now_s >= e.respawn_at_s;
  }
  /// A respawn that could not start: again in 1 s.
  void RespawnFailed(Entry* e, double now_s);
  /// The testbed fails (exit code 1).
  void Fail() { exit_code_ = 1; }
  /// "" or why the testbed fails: a respawned required process not ready again in time.
  std::string RespawnTimeout(double now_s) const;
  struct GroupCheck {
    bool ready = false;
    std::string failure;  // a process not ready in time
  };
  /// The group being started at now_s; `heard(host)`: whether that deputy was heard.
  GroupCheck CheckGroup(double now_s, const std::function<bool(const std::string&)>& heard,
                        const std::string& lcm_url) const;
  /// After a ready group: true when there is a next one (BeginGroup it), else all are started.
  bool NextGroup();
  /// Stopping begins: no respawn from now on.
  void BeginStop();
  /// A required process that exits with a code > 0 while stopping fails the testbed; its note.
  Note StoppedWith(const Entry& e, int exit_code);
  /// The summary printed at the end (header, a line per process).
  std::string Summary() const;

 private:
  LaunchSpec spec_;
  std::vector<Entry> entries_;
  std::string host_;
  size_t name_width_ = 7;  // "process", the summary's header
  size_t starting_group_ = 0;
  bool all_started_ = false;
  double group_started_at_s_ = 0;
  int exit_code_ = 0;
  bool stopping_ = false;
};

}  // namespace orbed::launcher
