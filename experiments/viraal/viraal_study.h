#pragma once
/// @file
/// The ViRAAl experiment without a bus: what `scripts/orbed run` does with five processes, done in
/// one program by calling the same code in the same order.
///
///   conductor (viraal/)         the scenario file's modes, trials and configurations; the errors
///                               against the truth (experiments/viraal/exchange.h,
///                               experiments/viraal/metrics.h)
///   headset (hmd_emulator/)     RunHeadsetTrial, the function orbed-hmd calls for a REQUEST_TRIAL,
///                               with the same seeds (process seed, session id, trial index)
///   registration server         RegistrationService, the core orbed-registration runs: trials in,
///                               the SE(3) mean on COMPUTE, the misalignment of the landmark pairs
///   arm (sim/)                  reaches each configuration exactly (the sim lands on its target), so
///                               the trial's q is the configuration in radians
///
/// The messages that would have crossed the bus are built and passed as they are (poses through
/// pose_t, joint vectors through the message arrays), so for the same seed, run id and files the
/// results equal results.json of the live run number for number (study_test checks it against the
/// pinned run in tests/integration/testdata). Sessions are "<run_id>-<mode>"; trial i of a mode is
/// made at configuration i mod K.
///
/// Frames: W world, R real robot base, V virtual robot base. Units as in experiments/viraal/results.h.
/// Threading: pure function of its inputs; reentrant.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "experiments/viraal/protocol.h"
#include "experiments/viraal/results.h"

namespace orbed::study {

struct StudyOptions {
  /// The conductor's scenario (experiments/viraal/viraal.yaml, flags applied).
  viraal::ScenarioConfig scenario;
  /// Robot model and scene; "" = the files shipped in the source tree.
  std::string urdf_path;
  std::string scene_path;
  /// Headset config files applied after the shipped ones (as orbed-hmd --config).
  std::vector<std::string> headset_config_paths;
  /// orbed-hmd's --seed (the per-trial seeds derive from it) and the conductor's (results.json).
  std::uint64_t seed{1};
  /// orbed-hmd's --user-seed: the emulated person (overrides the configs' user.seed when set).
  std::optional<std::uint64_t> user_seed;
  /// Session ids are "<run_id>-<mode>".
  std::string run_id{"study"};
  /// Called after each trial with (trials done, trials in all); may be empty.
  std::function<void(int, int)> progress;
};

/// Runs every mode of the scenario; throws std::runtime_error / std::invalid_argument on unreadable
/// files, a configuration outside the joint limits or a refused message (naming it).
viraal::RunResults RunViraalStudy(const StudyOptions& options);

/// One SE(3) mean of a group of consecutive trials of a session (GroupMeans).
struct GroupMean {
  int first_trial{0};  ///< the group's first trial, as an index into session.trials
  int num_trials{0};
  /// Measured as the conductor measures a session mean (experiments/viraal/exchange.h MeanError)
  /// over the group's configurations: against the real landmarks the user annotated in the group's
  /// trials (landmarks "gaze_real") when every one of them was annotated, else the truth's pairs;
  /// truth_misalignment_mm, translation_error_mm (at the robot centroid, averaged over the group's
  /// configurations) and rotation_error_deg against the truth; viewer_axes_mm in the trials'
  /// viewer frames when every trial has an eye.
  viraal::ErrorMeasures errors;
};

/// The paper's registration statistic (Sec. II-A, IV-B: the SE(3) average of N = 3 trials): the
/// trials of `session` taken `group_size` at a time in order (the last incomplete group left out),
/// each group averaged on SE(3) by the registration server's core with `method`
/// (registration_t.METHOD_*), its trials as results.json has them (q_deg, X_WV, X_WR), the
/// landmarks and centroid of `landmarks` on the robot of `urdf_path` ("" = the shipped model).
/// Throws std::invalid_argument for a group size below 1, std::runtime_error when the server has no
/// valid mean for a group.
std::vector<GroupMean> GroupMeans(const viraal::SessionResult& session, int group_size,
                                  const std::vector<std::string>& landmarks, int8_t method,
                                  const std::string& urdf_path = "");
/// The same with the scenario's landmarks and method and options' robot model.
std::vector<GroupMean> GroupMeans(const StudyOptions& options, const viraal::SessionResult& session,
                                  int group_size);

}  // namespace orbed::study
