#pragma once
/// @file
/// The launcher's side of its deputies (deputy_protocol.h): one Slot per process placed on another
/// host, a RemoteChild (a ChildHandle) per slot, the wanted state sent on DEPUTY_COMMAND to each
/// deputy every kDeputyPeriodS and at once on a change, and what each deputy says on DEPUTY_STATUS
/// read back into the slots.
///
/// A remote child is running from Start() until its deputy reports that instance exited (or could
/// not start); until the deputy is heard it is "starting" (pid 0). A deputy not heard for
/// kDeputySilentAfterS is reported silent once in the log, and back once it is heard again; its
/// children keep their last known state meanwhile (a partition is not an exit). Every command names
/// the run's folder (run_dir), which each deputy makes under its own logs folder; a remote child's
/// exit is printed here with the last lines it printed on its host (Drain at its exit).
///
/// Threading: the launcher's Run thread only (Tick from its timer, statuses from its handlers).

#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <orbed/deputy_status_t.hpp>

#include "procs/launcher/child.h"
#include "runtime/process.h"

namespace orbed::launcher {

inline constexpr double kDeputySilentAfterS = 3.0;

class DeputyLink {
 public:
  using Clock = std::chrono::steady_clock;
  /// `launcher_id` names this launcher in every command ("<launch>@<host>/<pid>"),
  /// `start_utime` is when it started [us since the epoch], `run_dir` the run folder's name (one
  /// path component, or "" for none).
  DeputyLink(Process* process, std::string launcher_id, int64_t start_utime, std::string run_dir);

  /// A handle on process `name` run by `deputy`, which stops it with `stop_signal` (when it stops
  /// it on its own: orphaned, replaced) and escalates a stop to SIGKILL after `stop_timeout_s`; the
  /// same slot (and instance count) for every call with that name.
  std::unique_ptr<ChildHandle> MakeChild(const std::string& deputy, const std::string& name, int stop_signal,
                                         double stop_timeout_s);
  /// The launcher is done: every deputy it used gets an empty command (sent three times), which
  /// makes it stop whatever still runs and follow the next launcher at once.
  void SayGoodbye();
  /// A deputy that followed this launcher and now reports following another or none (it timed
  /// this launcher out, e.g. across a long partition): its name, else "".
  std::string LostDeputy() const;

  /// Sends the commands that are due and notes deputies that fell silent.
  void Tick();
  /// Whether `deputy` was ever heard on DEPUTY_STATUS.
  bool Heard(const std::string& deputy) const;
  /// Whether `deputy` was heard within the last kDeputySilentAfterS.
  bool Reachable(const std::string& deputy) const;

  struct Slot {
    std::string deputy, name;
    // Wanted.
    int instance = 0;
    bool run = false;
    std::vector<std::string> argv;
    std::map<std::string, std::string> env;
    int stop_signal = 2;       // the signal of the stop asked for now
    int spec_stop_signal = 2;  // the launch file's
    double stop_timeout_s = 5.0;
    // Reported (for `instance` only once reported.instance == instance).
    int reported_instance = 0;
    int pid = 0;
    int state = -1;  // deputy_child_t::STATE_*, -1 before any report
    int exit_code = 0;
    int term_signal = 0;
    std::string detail;
    std::vector<std::string> last_lines;
  };
  /// The run folder's name sent to the deputies ("" = none).
  const std::string& run_dir() const { return run_dir_; }
  /// Marks `deputy`'s command as due at the next Tick.
  void Changed(const std::string& deputy) { due_[deputy] = true; }

 private:
  void OnStatus(const orbed::deputy_status_t& status, int64_t recv_utime);
  void Send(const std::string& deputy);

  Process* process_;
  std::string launcher_id_;
  int64_t start_utime_;
  std::string run_dir_;
  std::map<std::string, bool> followed_;  // by deputy: it reported following this launcher
  std::string lost_;
  std::map<std::string, std::unique_ptr<Slot>> slots_;  // by process name
  std::map<std::string, bool> due_;                     // by deputy
  std::map<std::string, Clock::time_point> last_sent_, last_heard_;
  std::map<std::string, bool> silent_;
};

}  // namespace orbed::launcher
