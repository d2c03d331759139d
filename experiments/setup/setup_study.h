#pragma once
/// @file
/// One set-up user without a bus: what `scripts/launch/setup.yaml` does with eight processes in
/// lockstep on the sim's clock, done in one thread by calling the same cores in the same order, so
/// that RunSetupUser returns the SetupRun a bus run of the same user writes to setup_results.json
/// (setup_study_test checks it against a pinned bus run in tests/integration/testdata).
///
/// What a set-up's numbers depend on, and so what is reproduced here:
///   - the alignments (headset modes): the headset's emulated trials (seeded by the process seed,
///     the session id "<run_id>-<task id>-<mode>" and the trial index; the session's map carried
///     from trial to trial) at the configurations the nested ViRAAl conductor moves the arm to, and
///     the registration server's SE(3) mean: the cores hmd::Headset and RegistrationService;
///   - the assistant's looks (AssistantMachine): the measured q and the motion state of the last
///     tick (IIWA_STATUS, ROBOT_STATE), the hologram's pose (the latest valid REGISTRATION), and the
///     eye and the SLAM error from the latest HMD_POSE / HMD_POSE_TRUTH pair at the moment it
///     looks: the live walk's sample at a multiple of 1/60 s of sim time, whose SLAM error is a
///     random walk stepped once per sample and whose walk time jumps by each emulated trial's
///     alignment time; on the fixed monitor, FIXED_VIEW's camera while one came within 2 s;
///   - the arm's motion (sim::ArmSim: speeds, limits, stops before a collision), which sets the sim
///     time of every look;
///   - the conductor's phases (SetupConductor), which also record the joints and the docking error.
/// So every core runs as on the bus, on the sim's clock: the sim's ticks (K = 10 steps of 5 ms),
/// and per tick the lockstep rounds of docs/sim-time.md: round 1 runs every follower's timers that
/// came due (at their deadlines, on the previous tick's state), then the tick's state goes out,
/// then every message is handled, each by its subscribers, until none is left (the bus's later
/// rounds). Messages are handled in the order they were sent; the lockstep design makes the
/// result independent of the order between senders (design.md §6), so one fixed order is the bus's.
/// What no decision reads is left out: the rendered streams (camera, reflective views, AR view,
/// the fixed monitor's JPEG: only its camera pose is passed on), GAZE_RAY, heartbeats, the logger.
///
/// Injected registration error (beyond the bus run, for the sweep): the REGISTRATION the assistant
/// receives is changed before it sees it (the hologram is drawn where that registration puts it;
/// the conductor's record keeps the measured alignment's errors): X_WV' = [R_W(a, tilt) · R_WV,
/// p_WV + offset · d_W], a shift of the virtual base by `offset_m` along the unit direction d_W and a
/// rotation by `tilt_rad` about the unit axis a through the virtual base's origin, both in W. With
/// `random_direction` d_W is uniform on the sphere and a uniform horizontal axis, drawn per set-up
/// from the user seed and the task id (InjectionFor).
///
/// Frames: W world, R real base, V virtual base. Units: m, rad inside; deg where the name says so.
/// Threading: RunSetupUser is a pure function of its options (reentrant; each call loads its own
/// models), so users run on any number of threads give the same results.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "experiments/setup/setup_conductor.h"

namespace orbed::setup {

/// A registration error added to every REGISTRATION the assistant receives (file comment).
struct RegistrationInjection {
  double offset_m{0};
  double tilt_rad{0};
  Eigen::Vector3d direction_W{Eigen::Vector3d::UnitX()};  ///< unit
  Eigen::Vector3d tilt_axis_W{Eigen::Vector3d::UnitY()};  ///< unit
  bool random_direction{false};
  bool active() const { return offset_m != 0 || tilt_rad != 0; }
};

/// X_WV moved by the injection with direction d_W and axis a (file comment).
Eigen::Isometry3d InjectRegistrationError(const Eigen::Isometry3d& X_WV, double offset_m, double tilt_rad,
                                          const Eigen::Vector3d& direction_W, const Eigen::Vector3d& axis_W);
/// The direction and axis of one set-up: the injection's own, or with random_direction drawn from
/// (user_seed, task_id): d uniform on the unit sphere, a uniform on the horizontal circle.
std::pair<Eigen::Vector3d, Eigen::Vector3d> InjectionFor(const RegistrationInjection& injection,
                                                         uint64_t user_seed, const std::string& task_id);

struct SetupUserOptions {
  std::string user{"u1"};  ///< task ids "<user>-<mode>-<k>"
  /// The person: orbed-hmd --user-seed, orbed-assistant --person-seed and orbed-setup --user-seed
  /// (the order of the modes unless `modes` is given).
  uint64_t user_seed{1};
  std::string run_id{"setup"};  ///< sessions "<run_id>-<task id>-<mode>"
  std::vector<int8_t> modes;    ///< empty: ModeOrderForSeed(user_seed)
  /// K: the (start, target) pairs drawn from the design per mode (or the plan's first K targets).
  int targets{3};
  int trials{3};  ///< alignments before each headset set-up (N)
  /// The design (orbed-setup's default, as `scripts/orbed study` launches it): UserDesignFor(
  /// design_path, scene_path, user_seed, targets) draws the patient and the K pairs; the patient's
  /// scene is the sim's collision world, the headset's, the monitor's and the conductor's (its
  /// retract after each set-up; the plan checks go to the sim), as the launch's `scene` argument.
  std::string design_path;  ///< "" = experiments/setup/design.json
  /// The scene (the launch's `scene` argument): "" = the drawn patient's (the design), or
  /// sim/models/scenes/trocar_or.yaml (the plan); with the design it fixes the patient to that
  /// scene's (orbed-setup --scene).
  std::string scene_path;
  /// The plan instead of the design (orbed-setup --plan / --start-deg): the plan's first K targets
  /// (plan_path), each from start_deg, no retract.
  bool use_plan{false};
  std::vector<double> start_deg{0, 20, 0, -60, 0, 40, 0};  ///< with use_plan
  bool perfect_registration{false};                        ///< orbed-setup --registration truth
  RegistrationInjection injection;
  /// Files; "" = the shipped ones (as the launch file: iiwa7.urdf, experiments/setup/targets.json,
  /// experiments/viraal/viraal.yaml, procs/assistant/assistant.yaml).
  std::string plan_path, scenario_path, assistant_config_path;
  /// Headset config files applied after the shipped ones (orbed-hmd --config).
  std::vector<std::string> headset_config_paths;
  /// orbed-hmd's --seed (the launch passes none: 1).
  uint64_t hmd_process_seed{1};
  /// The sim's start stamp [µs] (its wall clock at start on the bus): the stamps and request ids
  /// only; no number of the results depends on it.
  int64_t start_utime{1'700'000'000'000'000};
  /// The longest the run may take [s of sim time] before it is given up (a failed run).
  double max_sim_s{3600};
};

/// Runs one user; the SetupRun as orbed-setup would write it (run.ok false with the conductor's
/// reason when a phase failed). Throws std::runtime_error / std::invalid_argument on unreadable
/// files or options the conductor refuses.
SetupRun RunSetupUser(const SetupUserOptions& options);

}  // namespace orbed::setup
