#pragma once
/// @file
/// orbed-scenario's process: ViraalConductor (viraal_conductor.h, the run's phases, timeouts and
/// errors) on the bus.
///
///   Subscribes: ROBOT_STATE (robot_state_t: true X_WR, q, motion state), PLAN_CHECK_REPLY,
///               ALIGNMENT_TRIAL (alignment_trial_t, from orbed-hmd's emulated user),
///               REGISTRATION (registration_t), LANDMARK (landmark_t), MISALIGNMENT (misalignment_t).
///   Publishes:  what the conductor asks for: PLAN_CHECK_REQUEST, SESSION_CONTROL (START /
///               REQUEST_TRIAL / COMPUTE / STOP), IIWA_COMMAND, LANDMARK_REQUEST,
///               MISALIGNMENT_REQUEST; and
///               PROCESS_STATUS at 1 Hz (Process), where the conductor's refusals are counted.
///
/// Each decoded message goes to the conductor with the time it was handled, and a timer calls its
/// Tick() every tick_s; the actions it returns are carried out at once, in order. While the run
/// goes on, results.json (experiments/viraal/results.h) in results_dir is rewritten with status "partial" at
/// the start and whenever a trial or a mean is finished, so a conductor killed mid-run (SIGKILL)
/// leaves what it finished. When the conductor is done, results.json is written once more: on
/// success the table is printed and the process stops with exit code 0; on a failure "FAILED:
/// <reason>" is printed, the reason goes on the heartbeat and the exit code is 1 (results.json
/// says "failed", with what was finished). A stop from outside (signal, --duration-s) before the
/// end fails the run as "interrupted".
///
/// Resuming (resume_path, a results.json or the folder holding it): the earlier run's results are
/// read (experiments/viraal/results.h) and checked against this run (resume.h); the run id is the earlier
/// run's unless one is given (it must then be the same); the conductor keeps what they hold.
///
/// Clocks: the conductor's t_s and utime are the process clock (Process::ClockSeconds / ClockUtime:
/// monotonic seconds since the start and the wall clock, or with --sim-time the sim's).
/// Threading: everything on the Process::Run() thread.

#include <chrono>
#include <iosfwd>
#include <memory>
#include <string>

#include "experiments/viraal/results.h"
#include "experiments/viraal/viraal_conductor.h"
#include "runtime/process.h"

namespace orbed::scenario {

struct ScenarioOptions {
  /// The run: scenario, run id, tolerances, timeouts and channels. An empty run_id becomes
  /// "viraal-<UTC start time>"; the seed is taken from the process flags.
  ConductorOptions conductor;
  /// Folder of results.json; "" = $ORBED_LOG_DIR if set, else the working directory.
  std::string results_dir;
  /// An earlier run's results.json (or its folder) to resume; "" = a new run.
  std::string resume_path;
  /// Robot model for the landmark and centroid FK; "" = sim/models/iiwa7.urdf under
  /// $ORBED_SOURCE_DIR, else under the source tree this library was built from.
  std::string urdf_path;
  /// Period of the conductor's Tick() [s].
  double tick_s{0.01};
  /// Progress lines and the final table go here (nullptr = nowhere).
  std::ostream* out{nullptr};
};

/// `relative` under $ORBED_SOURCE_DIR if set, else under the source tree this library was built from.
std::string ScenarioSourcePath(const std::string& relative);

class ViraalScenario {
 public:
  /// Checks the numbers, loads the robot model and builds the conductor (std::invalid_argument /
  /// std::runtime_error with the reason), then opens LCM (std::runtime_error naming the URL).
  ViraalScenario(const orbed::CommonFlags& flags, const ScenarioOptions& options);
  ~ViraalScenario();

  /// Runs the experiment; returns 0 when it completed, 1 on a failure.
  int Run();
  orbed::Process& process() { return *process_; }
  const ViraalConductor& conductor() const { return *conductor_; }
  /// The conductor's results; once it is done, as written to results.json (rejected_inputs =
  /// every input the process refused or could not decode).
  const viraal::RunResults& results() const { return finished_ ? results_ : conductor_->results(); }
  /// Path of the results.json written at the end ("" before).
  const std::string& results_path() const { return results_path_; }

  /// The timer's callback (public so that tests can drive it).
  void Tick();

 private:
  ConductorTime Now() const;
  // Whether the conductor runs; starts it first if the process clock has begun (Run).
  bool Started();
  /// Carries out the conductor's actions in order, then finishes the run once it is done.
  void Apply(const ConductorActions& actions);
  void Finish();
  /// Rewrites results.json with status "partial" when a trial or a mean was finished since the last
  /// time (and at the first call).
  void WriteProgress();
  void Say(const std::string& line);

  ScenarioOptions options_;
  std::unique_ptr<ViraalConductor> conductor_;
  std::unique_ptr<orbed::Process> process_;
  bool finished_{false};
  bool started_{false};
  viraal::RunResults results_;
  std::string results_path_;
  int64_t progress_written_{-1};  // finished trials + means in the last results.json written
};

}  // namespace orbed::scenario
