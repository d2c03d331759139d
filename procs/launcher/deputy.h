#pragma once
/// @file
/// `orbed-launch --deputy NAME`: runs, on its host, the processes a launcher places there (launch
/// files' `host: NAME`), as procman's deputies do. It follows DEPUTY_COMMAND messages addressed to
/// NAME (deputy_protocol.h) and reports on DEPUTY_STATUS:
///   - a process whose wanted instance exceeds the one it has is started (Child: its own process
///     group, output printed here as "<name> | <line>"), with the command's env plus
///     ORBED_LCM_URL = the deputy's, ORBED_HOST = NAME, ORBED_LOG_PREFIXED = 1; the same instance
///     is never started twice, and a process that exits stays exited until the launcher asks for
///     the next instance (respawning is the launcher's decision);
///   - the command's run_dir names the run's folder: the deputy makes <log_root>/<run_dir> on its
///     own host and expands ${ORBED_LOG_DIR} in argv and env values (and sets ORBED_LOG_DIR) to
///     it, so a process keeps its state (journal, state file) on this host's disk, not on a path
///     that exists only on the launcher's host; a folder it cannot make is a failure to start;
///   - an exited child's report carries the last kMaxLastLines lines it printed (each cut to
///     kMaxLastLineBytes), so that the launcher's terminal says why it failed;
///   - `run: false` sends the process group its stop_signal (again whenever the wanted signal
///     changes, e.g. to SIGKILL), and SIGKILL after stop_timeout_s;
///   - a process missing from the command is stopped (SIGTERM, SIGKILL after 5 s);
///   - a `run: false` for an instance it never started (the start was lost) is reported as exited
///     ("stopped before it started"), so the launcher's stop completes;
///   - a command from a launcher that started later than the one followed makes that one current:
///     what the previous one started is stopped, and a process of the same name is started only
///     once its predecessor is gone; commands of an earlier launcher are ignored (no flapping
///     between two launches);
///   - a command listing no processes is the followed launcher's goodbye, and no command from it for
///     orphan_timeout_s means it is gone (a launcher that died must not leave processes behind; a
///     partition shorter than that changes nothing): either way everything it started is stopped
///     and the deputy follows nobody until the next launcher.
/// On SIGINT/SIGTERM it stops its processes (as above) and exits 0.
///
/// Anyone on the LCM group can start commands through a deputy: run deputies only on a group
/// confined to the lab (ttl=1 on a private network, as `--lan` does), never on a shared one.
///
/// Threading: one thread (Process::Run); children polled every 20 ms.

#include <chrono>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <orbed/deputy_command_t.hpp>
#include <orbed/deputy_status_t.hpp>

#include "procs/launcher/child.h"
#include "runtime/process.h"

namespace orbed::launcher {

struct DeputyOptions {
  /// Its name: the launch files' `host:`.
  std::string name;
  /// Searched first for commands without '/'.
  std::string bin_dir;
  /// This host's logs folder: run folders are made in it (relative: to the working folder).
  std::string log_root = "logs";
  /// Longer than the launch files' request deadline (60 s): a partition the run rides out must not
  /// make the deputy give up first.
  double orphan_timeout_s = 90.0;
};

class Deputy {
 public:
  using Clock = std::chrono::steady_clock;
  Deputy(const CommonFlags& flags, DeputyOptions options);
  ~Deputy();
  /// Until SIGINT/SIGTERM (or --duration-s); then stops its processes. Returns 0.
  int Run();
  Process& process() { return process_; }
  /// A command as if received (checks included): tests and fuzz targets.
  void OnCommand(const orbed::deputy_command_t& command);
  /// Polls the children, escalates overdue stops, applies the orphan timeout, sends the status.
  void Tick();
  /// The status it would send now.
  orbed::deputy_status_t Status() const;
  /// Whether any process it started is still running.
  bool AnyRunning() const;

 private:
  struct Managed {
    std::string name;
    int instance = 0;
    std::unique_ptr<Child> child;
    // Its last lines of output (at most kMaxLastLines after each Tick); on the heap, as the child
    // appends to it and a Managed moves between lists.
    std::unique_ptr<std::vector<std::string>> last_lines;
    bool failed_to_start = false;
    std::string detail;
    std::string prefix;
    int stop_signal = 2;  // the signal to use when asked to stop without one
    double stop_timeout_s = 5.0;
    int signal_sent = 0;        // the last stop signal sent, 0 = not stopping
    Clock::time_point kill_at;  // SIGKILL then, while stopping
  };
  void Start(Managed* managed, const orbed::deputy_process_t& wanted);
  void Stop(Managed* managed, int signal, double timeout_s);
  void StopAll(std::vector<Managed>* list, const char* why);
  // Stops what the followed launcher started and follows nobody.
  void Forget(const char* why);
  // A fresh entry for a process: `current` (its old instance SIGKILLed and moved to leaving_) or,
  // for nullptr, a new one in children_.
  Managed* Replace(Managed* current);

  DeputyOptions options_;
  CommonFlags flags_;
  Process process_;
  std::string launcher_;                     // the launcher followed ("" before the first command)
  std::string run_dir_;                      // its latest command's run_dir
  int64_t launcher_start_utime_ = 0;         // the last followed one's launcher_start_utime
  std::set<std::string> ignored_launchers_;  // earlier launchers already warned about
  Clock::time_point last_command_;
  std::vector<Managed> children_;  // the current launcher's, one per name
  std::vector<Managed> leaving_;   // stopping: an earlier launcher's, or replaced instances
  bool changed_ = false;
  Clock::time_point last_status_;
};

}  // namespace orbed::launcher
