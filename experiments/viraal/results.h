#pragma once
/// @file
/// The results of a ViRAAl run and their two renderings: results.json (documented in docs/studies.md)
/// and the text table orbed-scenario prints at the end.
///
/// Units: as named (mm, deg, s); poses X_WR (truth) and X_WV (chosen / mean) as
/// {"position_m":[x,y,z],"quaternion_wxyz":[w,x,y,z]} in the world W.
///
/// results.json, top level:
///   "run_id", "status" ("ok" | "failed" | "partial": written while the run goes on, so a conductor
///   that is killed leaves what it finished), "error" (one line, "" when ok or partial),
///   "resumed_from" (only in a run resumed from an earlier one's results: that file), "provenance"
///   (only in a run folder that has a provenance record: its file name, "provenance.json"), "seed",
///   "started_utime" [µs since the epoch], "duration_s" (wall clock of the run),
///   "translation_error_point" (what "translation_error_mm" measures), "misalignment_definition",
///   "landmarks" (link names), "X_WR" (truth at the first trial), "configurations_deg",
///   "rejected_inputs" (count of invalid messages the scenario refused),
///   "paper_reference" (Table 1 / Sec. III-B figures, mm),
///   "sessions": [ {"mode", "session_id", "display_mode", "num_mirrors", "capture_waypoints" (only
///                  when the scenario chose them: one name per display; absent: the headset's own),
///                  "trials": [ {"index", "q_deg", "translation_error_mm", "rotation_error_deg",
///                               "misalignment_mm", "base_translation_error_mm",
///                               "flange_translation_error_mm", "misalignment_axes_mm" [t̄x,t̄y,t̄z],
///                               "misalignment_mean_pair_distance_mm", "viewer_axes_mm" ([t̄x, t̄y, t̄z]
///                               in the trial's viewer frame S, metrics.h; only when the trial was
///                               annotated), "viewer_eye_W_m" (S's eye [m], the same trials), "landmarks"
///                               ("gaze" | "gaze_real" (a mean) | "truth"), "truth_misalignment_mm" (both
///                               absent in files written before ALIGNMENT_TRIAL's contract change 5: read as
///                               "truth" and misalignment_mm), "user_duration_s", "user_id", "X_WV", "X_WR",
///                               "annotated_real_W_m" ([[x, y, z], ...] [m], the triangulated real landmarks;
///                               [] without annotation; absent in older files, read as []),
///                               "tracking_faults": {"losses", "relocalizations", "wait_s",
///                                                   "repeats"} (only on a trial whose user met
///                                                   a tracking fault while aligning: see
///                                                   TrackingFaults)} ],
///                  "trial_statistics": {"<measure>": {"mean", "std"}} over the trials (std with
///                                      N − 1; 0 for one trial),
///                  "table1": {"num_trials", "axes_mean_mm", "axes_std_mm", "mean_mm", "std_mm"}
///                            (the paper's statistic over the trials: Table1Row),
///                  "table1_viewer": the same in the viewer frames (only when every trial has
///                                   viewer_axes_mm),
///                  "mean": {"translation_error_mm", "rotation_error_deg", "misalignment_mm",
///                           "base_translation_error_mm", "flange_translation_error_mm",
///                           "misalignment_axes_mm", "misalignment_mean_pair_distance_mm",
///                           "viewer_axes_mm" (each pair in the frame of the trial at its q; only when
///                           every trial has an eye),
///                           "landmarks", "truth_misalignment_mm", "X_WV", "num_used", "rejected_indices",
///                           "rotation_rms_deg", "translation_rms_mm", "iterations", "converged", "unique"} }
///                           ]
/// A failed or partial run still writes what it had: the sessions and trials finished so far ("mean"
/// is null for a session that did not get one).
///
/// ReadResultsFile reads the document back (the conductor resuming a run), checked like any input
/// from outside (base/json_fields.h): every field with its type and range, bounded counts, unit
/// quaternions; "trial_statistics", "table1" and "table1_viewer" are derived, not read; "started_utime" and
/// "duration_s" may be absent (a pinned file leaves them out).
///
/// Threading: plain data and pure functions.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace orbed::viraal {

/// The error measures of one pose against the truth (see experiments/viraal/metrics.h for the definitions).
struct ErrorMeasures {
  double translation_error_mm{0};  ///< at the robot's centroid
  double rotation_error_deg{0};
  double misalignment_mm{0};  ///< paper Table 1: ‖t̄‖₂ over the landmark pairs
  double base_translation_error_mm{0};
  double flange_translation_error_mm{0};
  Eigen::Vector3d misalignment_axes_mm{Eigen::Vector3d::Zero()};  ///< t̄ = mean |virtual − real| per axis
  double misalignment_mean_pair_distance_mm{0};                   ///< mean of the pair distances
  /// Where the landmark pairs of the three misalignment fields above came from: "gaze" (the user's
  /// annotation, triangulated by orbed-registration: the paper's measurement), "gaze_real" (a
  /// session mean: the real landmarks as annotated in the session's trials, the virtual ones placed
  /// by the mean) or "truth" (the link origins placed with X_WR and X_WV: a trial nobody annotated,
  /// and a mean of a session with such a trial).
  std::string landmarks{"truth"};
  /// ‖t̄‖₂ of the truth pairs, whatever `landmarks` says (= misalignment_mm when it says "truth").
  double truth_misalignment_mm{0};
  /// t̄ of the same pairs as misalignment_axes_mm, per axis of the viewer frame S instead of W
  /// (metrics.h ViewerFrame: z the line of sight from where the person aligned); unset when no eye
  /// is known (a trial nobody annotated, a mean of a session with such a trial).
  std::optional<Eigen::Vector3d> viewer_axes_mm;
};

/// The tracking faults the user met while aligning (ALIGNMENT_TRIAL's contract change 2 fields).
struct TrackingFaults {
  int losses{0};           ///< LIMITED or LOST episodes
  int relocalizations{0};  ///< RELOCALIZED samples
  double wait_s{0};        ///< stood waiting for tracking, part of user_duration_s [s]
  int repeats{0};          ///< alignments re-done after the hologram jumped

  bool any() const { return losses != 0 || relocalizations != 0 || wait_s != 0 || repeats != 0; }
};

struct TrialResult {
  int index{0};
  std::vector<double> q_deg;
  ErrorMeasures errors;
  double user_duration_s{0};  ///< the trial's duration_s (emulated time for orbed-hmd)
  std::string user_id;
  Eigen::Isometry3d X_WV{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};
  TrackingFaults tracking_faults;  ///< written only when any()
  /// The real robot's landmarks as the user annotated them, triangulated (in the headset's map, W)
  /// [m], in the scenario's landmark order; empty when nobody annotated. What the session mean is
  /// measured against (exchange.h MeanError), kept here so that a resumed run measures it too.
  std::vector<Eigen::Vector3d> annotated_real_W_m;
  /// Where the person stood when aligning (exchange.h AlignmentViewpoint), in the headset's map (W)
  /// [m]: the eye of the trial's viewer frame, kept so that a resumed run's mean gets its frames.
  std::optional<Eigen::Vector3d> viewer_eye_W_m;
};

struct MeanResult {
  ErrorMeasures errors;
  Eigen::Isometry3d X_WV{Eigen::Isometry3d::Identity()};
  int num_used{0};
  std::vector<int> rejected_indices;
  double rotation_rms_deg{0};
  double translation_rms_mm{0};
  int iterations{0};
  bool converged{false};
  bool unique{false};
};

struct SessionResult {
  std::string mode;
  std::string session_id;
  int display_mode{0};
  int num_mirrors{0};
  /// Where the displays captured: the waypoint names the conductor sent in START (one per
  /// display); empty: the headset's own (hmd.displays), and always for a mode without displays.
  std::vector<std::string> capture_waypoints;
  std::vector<TrialResult> trials;
  std::optional<MeanResult> mean;
};

struct RunResults {
  std::string run_id;
  bool ok{false};
  bool partial{false};  ///< not ok, not failed: the run goes on (status "partial")
  std::string error;
  std::string resumed_from;  ///< the results this run resumed ("" = none)
  std::string provenance;    ///< the run folder's provenance record ("" = none; base/run_folder.h)
  uint64_t seed{0};
  int64_t started_utime{0};
  double duration_s{0};
  std::vector<std::string> landmarks;
  std::vector<std::vector<double>> configurations_deg;
  std::optional<Eigen::Isometry3d> X_WR;
  int64_t rejected_inputs{0};
  std::vector<SessionResult> sessions;
};

/// Sample mean and standard deviation (N − 1 denominator; 0 for fewer than two values).
struct MeanStd {
  double mean{0};
  double std{0};
};
MeanStd ComputeMeanStd(const std::vector<double>& values);

/// The paper's Table 1 statistic over the trials of one mode. Each trial contributes its per-axis
/// error t̄_i = (t̄x, t̄y, t̄z) [mm]: the mean |virtual − real| over its landmark pairs, per axis of W
/// (misalignment_axes_mm). Per axis, the mean and the sample standard deviation (N − 1; 0 for one
/// trial) over the trials; the row's two figures are the L2 norms of those two vectors (the paper's
/// means (17.4, 11.9, 21.6) give its 30.2 mm). This is not the mean of the per-trial norms ‖t̄_i‖₂
/// (trial_statistics' misalignment_mm), which is never smaller: ‖mean_i t̄_i‖₂ ≤ mean_i ‖t̄_i‖₂ by
/// the triangle inequality.
struct Table1Row {
  int num_trials{0};
  Eigen::Vector3d axes_mean_mm{Eigen::Vector3d::Zero()};
  Eigen::Vector3d axes_std_mm{Eigen::Vector3d::Zero()};
  double mean_mm{0};  ///< ‖axes_mean_mm‖₂
  double std_mm{0};   ///< ‖axes_std_mm‖₂
};
Table1Row ComputeTable1Row(const std::vector<Eigen::Vector3d>& trial_axes_mm);
/// The row of a session's trials (their misalignment_axes_mm).
Table1Row SessionTable1Row(const SessionResult& session);
/// The same statistic in the viewer frames (the trials' viewer_axes_mm); unset when a trial has none.
std::optional<Table1Row> SessionViewerTable1Row(const SessionResult& session);

/// results.json text (pretty-printed, 2 spaces).
std::string ResultsJson(const RunResults& results);

/// The end-of-run table: one row per trial and per mean, then the paper's figures for comparison.
std::string ResultsTable(const RunResults& results);

/// Reads results.json back; `path` is the file or the folder holding it. Throws JsonReadError
/// (base/json_fields.h) naming the key of the first problem.
RunResults ReadResultsFile(const std::string& path);
RunResults ParseResultsJson(const std::string& text, const std::string& source);

/// Writes `text` to `dir`/results.json through a temporary file and a rename (a reader never sees a
/// half-written file); returns the path. Throws std::runtime_error naming the path on failure.
std::string WriteResultsFile(const std::string& dir, const std::string& text);

}  // namespace orbed::viraal
