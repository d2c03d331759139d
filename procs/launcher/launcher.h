#pragma once
/// @file
/// orbed-launch's shell (its core, the launch plan's decisions, is launch_plan.h): starts a launch file's
/// groups in order, each group's processes together, and waits for every process to be ready (its first
/// PROCESS_STATUS heartbeat from its own pid, unless `ready: none`) before starting the next group; a process
/// that is not ready in time stops the testbed with an error naming it. While running it re-emits each
/// child's output prefixed with the child's name, restarts children marked `respawn` (at once, then with a
/// growing back-off if they keep dying within a second), and stops the testbed when a required child fails or
/// a child marked `exit_stops_all` exits (one killed by a signal: an error, "before it finished"). A
/// respawned process is ready again at its new instance's first heartbeat; a required one that is
/// not ready again within its ready_timeout_s of dying (e.g. it keeps dying at start) stops the
/// testbed with an error naming it. A process that exits with kExitCannotWrite (74, process.h: it
/// cannot write its output, e.g. the logger on a full disk) is never respawned, and a required one
/// stops the testbed with its last output line in the error. On SIGINT/SIGTERM or after
/// --duration-s it stops the groups in reverse order: each child gets its stop_signal, then
/// SIGKILL after stop_timeout_s.
///
/// Run folders: the launch file's ${ORBED_LOG_DIR} is expanded where a process runs (the CLI
/// parses the file with it deferred): to `log_dir` for the launcher's own children, and by each
/// deputy to <its --log-root>/<the run's name> on its host (deputy_command_t.run_dir: log_dir's
/// name after those of the run folders it is in, joined by '.', e.g. "study-<time>-<random>.setup-u1"),
/// so every process keeps its state on its own host's disk, in a folder no other run uses; with a
/// shared disk and the logs folder as log root, a top-level run's is the launcher's folder itself.
///
/// Children get: --name <name> appended (heartbeat-ready processes, unless args have --name),
/// ORBED_LCM_URL = the launcher's LCM URL, ORBED_HOST = the launcher's host name,
/// ORBED_LOG_PREFIXED=1 (their log lines then omit the name), plus the env of their spec.
///
/// Across hosts: a process whose `host:` is not the launcher's own host name is started, watched,
/// restarted and stopped the same way through the deputy of that name (`orbed-launch --deputy
/// NAME` on that host; deputy_link.h, deputy.h), which prints its output there. A deputy never
/// heard makes the process's readiness time out with an error naming the deputy; a deputy that
/// falls silent (a partition) is logged, and its processes keep their last known state until it
/// is heard again.
///
/// Exit code: 0, or 1 when a required process failed (kExitCannotWrite included) or was not ready
/// in time, or the exit code of an `exit_stops_all` process.
///
/// Killed outright (SIGKILL), the launcher takes its local children with it (PR_SET_PDEATHSIG,
/// child.h); its deputies stop theirs once they have heard nothing from it for their orphan timeout.
///
/// Threading: one thread (Process::Run); children are polled every 20 ms.

#include <memory>
#include <string>
#include <vector>

#include <orbed/process_status_t.hpp>

#include "procs/launcher/child.h"
#include "procs/launcher/deputy_link.h"
#include "procs/launcher/launch_file.h"
#include "procs/launcher/launch_plan.h"
#include "runtime/process.h"

namespace orbed::launcher {

class Launcher {
 public:
  /// `bin_dir` is searched first for commands without '/'. `host` is this host's name: processes
  /// without `host:` or with this one run here. `log_dir` is the run's folder here ($ORBED_LOG_DIR;
  /// "" = none): what ${ORBED_LOG_DIR} left in `spec` expands to (see the file comment).
  Launcher(const CommonFlags& flags, LaunchSpec spec, std::string bin_dir, std::string host,
           std::string log_dir = "");
  ~Launcher();

  int Run();
  /// The launcher's own bus scaffold (its PROCESS_STATUS subscription: tests and fuzz targets).
  Process& process() { return process_; }

 private:
  std::unique_ptr<ChildHandle> MakeChild(const LaunchPlan::Entry& e);
  void Tick();
  // Starts entry i's child (again); false when it could not.
  bool StartProcess(size_t i);
  void StartGroup(size_t group);
  void HandleExit(size_t i);
  void StopEverything();
  void FailTestbed(const std::string& reason);

  CommonFlags flags_;
  LaunchPlan plan_;
  std::string bin_dir_;
  std::string host_;
  std::string log_dir_;
  Process process_;
  DeputyLink deputies_;
  std::vector<std::unique_ptr<ChildHandle>> children_;  // entry i's child
  double launch_started_at_s_ = 0;
};

}  // namespace orbed::launcher
