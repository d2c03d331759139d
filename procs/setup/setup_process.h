#pragma once
/// @file
/// orbed-setup: one user's part of the robot set-up study (SetupConductor, setup_conductor.h) on
/// the bus.
///
///   Subscribes: ROBOT_STATE, COLLISION_STATUS (clearance during each set-up), PLAN_CHECK_REPLY,
///   ALIGNMENT_TRIAL, REGISTRATION, LANDMARK, MISALIGNMENT (for
///               the alignments before the headset modes' set-ups, as orbed-scenario), SETUP_RESULT.
///   Publishes:  what the conductor asks for: SESSION_CONTROL, PLAN_CHECK_REQUEST,
///               LANDMARK_REQUEST, MISALIGNMENT_REQUEST and IIWA_COMMAND of the alignments; IIWA_COMMAND
///               parking the arm; SETUP_TASK; with --registration truth, REGISTRATION (the true base pose).
///
/// setup_results.json (SetupRunJson) in results_dir is rewritten with status "partial" after each
/// set-up and once at the end ("ok" or "failed"); then the process stops: exit 0 on success, 1 on a
/// failure (the reason on stdout and the heartbeat) or when stopped from outside before the end.
///
/// The targets and starts: by default the user's draw from the design catalog (--design,
/// UserDesignFor): the patient (fixed by --scene when the launch gives the sim's scene) and K
/// (start, target) pairs, the same for every mode; with --plan or --start-deg the plan's first K
/// targets, each from the one start (as before the design).
///
/// The user's order of the three modes: given (ModeOrderFromNames), or drawn from the user seed
/// (ModeOrderForSeed, setup_conductor.h), so a study's users meet the modes in randomized orders as
/// the paper's did, reproducibly.
///
/// Clocks: the process clock (Process::ClockSeconds / ClockUtime: monotonic and wall, or with
/// --sim-time the sim's) for the conductor's t_s and utimes. Threading: everything on the
/// Process::Run thread.

#include <chrono>
#include <iosfwd>
#include <memory>
#include <string>

#include "experiments/setup/design.h"
#include "experiments/setup/setup_conductor.h"
#include "runtime/process.h"

namespace orbed::setup {

class SetupProcess {
 public:
  /// Throws std::invalid_argument / std::runtime_error for bad options or an unreadable model.
  SetupProcess(const CommonFlags& flags, const SetupOptions& options, const std::string& urdf_path,
               const std::string& results_dir, std::ostream* out);
  /// Starts the conductor (Run() does; public for the fuzz target, which feeds the handlers
  /// without running). Once only.
  void Start();
  int Run();
  Process& process() { return process_; }

 private:
  // Whether the conductor runs; starts it first if the process clock has begun (Run).
  bool Started();
  void Apply(SetupConductor::Actions actions);
  ConductorTime Now() const;
  void Write(bool partial);

  Process process_;
  std::unique_ptr<SetupConductor> conductor_;
  std::string results_dir_;
  std::ostream* out_;
  size_t written_setups_{0};
  bool finished_{false};
  bool started_{false};
};

/// orbed-setup's command line (flags: --help). Exit 0 when every set-up finished; 1 on a failure; 2
/// or CLI11's usage code (106-109) on bad arguments.
int RunSetup(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::setup
