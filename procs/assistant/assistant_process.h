#pragma once
/// @file
/// orbed-assistant: the emulated set-up assistant (assistant.h) on the bus. It moves the real arm
/// joint by joint, from joint 1 to the flange, to where the target looks right to it, through
/// IIWA_COMMAND, so the sim's speeds, limits and collision stops hold.
///
///   Subscribes: GUIDANCE (the target and the guidance mode: checked by guidance::CheckGuidance; the
///               errors and the next joint it carries are NOT read: the person does not see numbers,
///               only the virtual robot or the monitor's picture), IIWA_STATUS (the measured q,
///               sim/iiwa_status_check.h), ROBOT_STATE (the true X_WR and the motion state),
///               REGISTRATION (headset modes: the latest valid X_WV_mean is where the hologram is
///               drawn), HMD_POSE and HMD_POSE_TRUTH (optional: the pair of one seq gives the eye,
///               and the SLAM error A = X_WH_true · X_WH_est⁻¹ that moves the hologram in the world),
///               FIXED_VIEW (optional, orbed-fixed-display: the monitor's camera position is its X_WC's,
///               while one came within fixed_view_stale_s and it lies 0.3-20 m from the base; else
///               the config's monitor.camera_m).
///   Publishes:  IIWA_COMMAND (the measured q with the joint being moved set to where the person
///               puts it; re-sent every command_resend_s until the arm is there and at rest, or
///               stopped by a limit or a collision: then the joint stays where the sim stopped it).
///
/// Tasks: by default the assistant serves SETUP_TASK (setup_task_t from orbed-setup, checked by
/// guidance::CheckSetupTask): a task with a new request id starts a set-up (a repeat of the
/// current one changes nothing; a repeat of a finished one gets its SETUP_RESULT again), and the
/// set-up waits for a GUIDANCE showing that task's target and mode. With --once it carries out the
/// first GUIDANCE's target without a task and stops.
///
/// The state machine is the core's (AssistantMachine, assistant_machine.h: unit-tested in emulated
/// time); this shell checks and converts what arrives, hands it to the machine with the process
/// clock, and publishes, logs and writes what the machine returns.
///
/// A set-up: wait for GUIDANCE, IIWA_STATUS, ROBOT_STATE with the arm at rest and, in the headset
/// modes, a REGISTRATION; then for each joint, looks_per_joint looks (the first over the whole
/// range, the others within correction_window_deg), each followed by the move; then publish
/// SETUP_RESULT (setup_result_t) for a task, write the result file (--result) and, with --once, stop.
/// Execution time is the time model's (assistant.h), not the wall clock's: the sim moves at the iiwa's own
/// speeds, a person's hand more slowly. A move that does not finish within move_timeout_s fails the run (exit
/// 1).
///
/// Result file (JSON): mode, seed, person_scale, q_start_deg, q_target_deg, q_reached_deg (the
/// measured joints at the end), error_deg (|reached − target| per joint), twisting (1/0 per joint,
/// from GUIDANCE), ranges (per joint, at its first look: how many separate ranges looked right),
/// execution_s, headset_pose (whether HMD poses were used).
///
/// Clocks: the process clock (Process::ClockSeconds / ClockUtime; with --sim-time the sim's) runs
/// the step timer, the move timeout, the command re-sends and the monitor's staleness, and stamps
/// IIWA_COMMAND and SETUP_RESULT: with the sim faster than real time, all of them keep their
/// sim-time relation to the arm's motion.
///
/// Threading: everything on the Process::Run thread.

#include <optional>
#include <string>
#include <vector>

#include "lcmtypes/contract/channels.h"
#include "procs/assistant/assistant.h"
#include "procs/assistant/assistant_machine.h"
#include "runtime/process.h"
#include "sim/robot_model.h"

namespace orbed::assistant {

struct AssistantOptions {
  std::string urdf_path;         ///< "" = the shipped model
  std::string config_path;       ///< "" = procs/assistant/assistant.yaml
  std::optional<uint64_t> seed;  ///< overrides the config's seed
  std::string result_path;       ///< "" = no file
  bool once{false};              ///< carry out GUIDANCE's target without a SETUP_TASK, then stop
  double step_period_s{0.02};
  double command_resend_s{0.25};
  double move_timeout_s{30.0};
  /// A joint within this of where the person put it, with the arm at rest, has arrived [deg].
  double arrived_deg{0.05};
  std::string guidance_channel{channels::kGuidance};
  std::string iiwa_status_channel{channels::kIiwaStatus};
  std::string robot_state_channel{channels::kRobotState};
  std::string registration_channel{channels::kRegistration};
  std::string hmd_pose_channel{channels::kHmdPose};
  std::string hmd_pose_truth_channel{channels::kHmdPoseTruth};
  std::string iiwa_command_channel{channels::kIiwaCommand};
  std::string setup_task_channel{channels::kSetupTask};
  std::string setup_result_channel{channels::kSetupResult};
  std::string fixed_view_channel{channels::kFixedView};
  double fixed_view_stale_s{2.0};
};

class AssistantProcess {
 public:
  /// Throws std::runtime_error / std::invalid_argument for an unreadable model or config.
  AssistantProcess(const CommonFlags& flags, const AssistantOptions& options);
  int Run() { return process_.Run(); }
  Process& process() { return process_; }
  const std::optional<SetupResult>& result() const { return machine_.result(); }
  const AssistantMachine& machine() const { return machine_; }
  /// The timer's work: the machine's Step at the process clock, its output published (public for
  /// the fuzz target, which has no timer running).
  void Step();

 private:
  Process process_;
  sim::RobotModel model_;
  AssistantOptions options_;
  AssistantMachine machine_;  // the state machine (assistant_machine.h)
};

/// orbed-assistant's command line (flags: --help). Exit 0; 2 or CLI11's usage code (106-109) on bad
/// arguments; 1 when it cannot start or a move times out.
int RunAssistant(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::assistant
