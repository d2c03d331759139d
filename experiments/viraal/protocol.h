#pragma once
/// @file
/// The ViRAAl scenario file (experiments/viraal/viraal.yaml): which display modes to run and in which
/// order, how many trials per mode, the joint configurations the robot takes for the trials, and
/// the landmarks of the paper's misalignment protocol. Every key is checked; unknown keys and bad
/// values are errors naming the file, the line and what was expected.
///
/// trials, modes, reflective_mirrors, method and capture_waypoints are optional: an absent key keeps the
/// ScenarioConfig default, which is the value written here and the value experiments/viraal/viraal.yaml ships
/// (protocol_test.cc checks that the three agree); configurations_deg and landmarks are required.
/// @code{.yaml}
/// trials: 3                        # per mode, 1..1000 (trial i uses configuration i mod K)
/// modes: [ar_reflective, ar]       # run order; each of ar_reflective | ar, no repeats
/// reflective_mirrors: 1            # num_mirrors of the ar_reflective mode, >= 1
/// method: karcher                  # chordal | karcher | robust (registration_t.METHOD_*)
/// capture_waypoints: []            # where each display captures: reflective_mirrors waypoint names
///                                  # of the headset's walk, e.g. [foot_end] ([] = its hmd.displays)
/// configurations_deg:              # required: K >= 1 joint vectors q1..q7 [deg], pairwise distinct
///   - [0, 30, 0, -60, 0, 45, 0]
/// landmarks: [iiwa_link_4, iiwa_link_6, iiwa_link_ee]   # required: link origins, >= 1 (paper: 3)
/// @endcode
///
/// Joint limits and collisions are not checked here (no model): ViraalConductor checks the limits
/// against the URDF and asks orbed-iiwa-sim (PLAN_CHECK_REQUEST) about collisions before use.
///
/// Threading: plain data; the loaders are reentrant.

#include <cstdint>
#include <string>
#include <vector>

#include <orbed/alignment_trial_t.hpp>
#include <orbed/registration_t.hpp>

namespace orbed::viraal {

/// One display mode of the experiment.
struct ModeSpec {
  std::string name;        ///< "ar_reflective" or "ar"
  int8_t display_mode{0};  ///< alignment_trial_t::MODE_*
  int32_t num_mirrors{0};
};

/// num_mirrors of the ar_reflective mode when the file does not say (reflective_mirrors).
inline constexpr int kDefaultReflectiveMirrors = 1;

struct ScenarioConfig {
  int trials{3};
  /// In run order: AR with a reflective display first, then AR alone.
  std::vector<ModeSpec> modes{
      {"ar_reflective", orbed::alignment_trial_t::MODE_AR_REFLECTIVE, kDefaultReflectiveMirrors},
      {"ar", orbed::alignment_trial_t::MODE_AR, 0}};
  int8_t method{orbed::registration_t::METHOD_KARCHER};
  /// Where each display of the reflective mode captures its frame, waypoints of the headset's walk
  /// in display order, sent with START (session_control_t, contract change 6); empty = the
  /// headset's own hmd.displays. Otherwise one per display of every reflective mode.
  std::vector<std::string> capture_waypoints;
  std::vector<std::vector<double>> configurations_deg;
  std::vector<std::string> landmarks;
};

/// The file shipped in the source tree, relative to the repository root.
inline constexpr const char* kDefaultScenarioRelativePath = "experiments/viraal/viraal.yaml";

/// Loads and checks a scenario file; throws std::runtime_error "file:line: key: what, expected ...".
ScenarioConfig LoadScenarioFile(const std::string& path);
ScenarioConfig LoadScenarioString(const std::string& yaml_text, const std::string& source_name);

/// "ar_reflective" / "ar" → a ModeSpec (the reflective mode with `reflective_mirrors` displays);
/// throws std::invalid_argument naming the accepted names otherwise.
ModeSpec ModeFromName(const std::string& name, int reflective_mirrors);

/// "q1,q2,...,q7" [deg] → numbers; throws std::invalid_argument naming `what` on a bad list.
std::vector<double> ParseJointList(const std::string& text, const std::string& what);

/// Applies command-line overrides: `trials` (> 0), `modes` ("ar_reflective,ar" in run order; the
/// reflective mode keeps the file's mirror count, else 1) and `q_deg` (each "q1,...,q7" [deg],
/// replacing the file's list). Empty / 0 leaves the file's value. Throws std::invalid_argument.
void ApplyOverrides(ScenarioConfig* config, int trials, const std::string& modes,
                    const std::vector<std::string>& q_deg);

/// Checks counts, joint-vector sizes (7), finiteness and pairwise distinctness (some joint differs
/// by more than 1 deg); throws std::invalid_argument with the reason. Used after flags override
/// the file.
void ValidateScenarioConfig(const ScenarioConfig& config, int num_joints);

}  // namespace orbed::viraal
