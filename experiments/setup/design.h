#pragma once
/// @file
/// The set-up study's design catalog and each user's draw from it: patients, trocar ports, target
/// configurations and parked start configurations, so that no single start or target makes the
/// study's numbers (docs/studies.md, "The design").
///
/// The catalog (experiments/setup/design.json, written by `orbed-design catalog`, design_main.cc)
/// is made from a DesignSpec (DefaultDesignSpec(): every value with its source or "chosen"):
///   - patients: one scene file each (sim/models/scenes/), the same OR with the patient's torso box
///     of another size; the sim of a user's run loads that scene (scripts/launch/base.yaml's
///     `scene` argument), so the arm collides with the patient its targets were planned for;
///   - ports: a skin point on the torso's top face, given as an offset from the umbilicus (the torso
///     box's centre + umbilicus_offset_m, on its top face), and an insertion direction tilted
///     port_tilt_deg from the downward vertical toward the operative field's centre (the umbilicus +
///     field_offset_m); the docking point stands stand_off_m out of the skin against the insertion
///     direction (the cannula's top), as in trocar_or.yaml;
///   - targets: for each (patient, port) and each of the 8 branches (signs of the bending joints 2,
///     4, 6), the planner's best docking configuration in that branch (sim/trocar_plan.h with
///     joint_signs; its clearance and min_bend_deg rules), kept when the straight joint-space
///     segments between it and every start, and to the first alignment configuration, keep
///     path_clearance_m (the sim moves straight in joint space and stops before a collision:
///     sim/manual_arm.h); id "<patient>/<port>/<k>", k = 1.. in branch order;
///   - starts: parked configurations, each checked collision-free with min_clearance_m in every
///     patient's scene, and its straight segments to and from the alignment configurations with
///     path_clearance_m (the conductor parks the arm after the alignments).
///
/// The draw (DrawUserDesign): from a user seed, the patient (uniform over the catalog's) and K
/// (start, target) pairs: K distinct targets of that patient (uniform without repetition, all
/// ports pooled) and for each a start drawn independently (uniform, with repetition). Every mode
/// of the user runs the same pairs in the same order (SetupConductor), so modes stay paired.
///
/// Relation of a start to a target (BendingRelation): over the bending joints 2, 4, 6 (indices 1,
/// 3, 5), "same" when every one has the start's sign, "mirror" when every one has the opposite
/// sign, "mixed" otherwise (a start joint within 1 deg of 0 has no sign: the pair is mixed).
///
/// Frames: scene W (sim/scene.h); joint angles in deg in files and here. Threading: pure functions
/// (MakeDesignCatalog builds its own collision worlds); deterministic for the spec's seed.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace orbed::setup {

struct DesignPatient {
  std::string name;
  std::string scene;  ///< relative to the source tree
  std::string source;
};

struct DesignPort {
  std::string name;
  Eigen::Vector2d offset_m{Eigen::Vector2d::Zero()};  ///< skin point − umbilicus in W's x, y [m]
  std::string source;
};

struct DesignStart {
  std::string name;
  std::vector<double> q_deg;
  std::string why;
};

struct DesignSpec {
  std::vector<DesignPatient> patients;
  std::vector<DesignPort> ports;
  std::vector<DesignStart> starts;
  Eigen::Vector2d umbilicus_offset_m{0.1, 0.0};  ///< umbilicus − torso centre in W's x, y [m]
  Eigen::Vector2d field_offset_m{-0.08, 0.0};    ///< operative field's centre − umbilicus [m]
  double port_tilt_deg{15.0};
  double stand_off_m{0.05};
  /// The torso: the scene object of this name (a box) in every patient's scene.
  std::string torso_object{"patient_torso"};
  /// The alignment configurations the headset modes move through before parking [deg]
  /// (experiments/viraal/viraal.yaml, read by the catalog command).
  std::vector<std::vector<double>> alignment_deg;
  // The planner's rules (sim/trocar_plan.h) and the path rule.
  double min_clearance_m{0.05};
  double min_bend_deg{10.0};
  double path_clearance_m{0.02};
  double path_step_deg{1.0};
  std::uint64_t seed{1};
  int ik_starts{48};
};

/// The shipped spec: 3 patients, 4 ports, 4 starts (their sources in design.cc).
DesignSpec DefaultDesignSpec();

struct CatalogPort {
  std::string patient, port;
  Eigen::Vector3d p_W_skin{Eigen::Vector3d::Zero()}, p_WT{Eigen::Vector3d::Zero()};
  Eigen::Vector3d insertion_direction_W{-Eigen::Vector3d::UnitZ()};
  int branches_tried{0}, branches_found{0}, branches_kept{0};
};

struct CatalogTarget {
  std::string id;  ///< "<patient>/<port>/<k>"
  std::string patient, port;
  std::string branch;  ///< signs of joints 2, 4, 6, e.g. "+-+"
  std::vector<double> q_deg;
  double clearance_m{0};
  double path_clearance_m{0};  ///< the smallest over its segments to the starts and alignment
  std::string worst_segment;   ///< the segment of that smallest clearance: a start's id or "alignment"
};

struct CatalogStart {
  std::string id;
  std::vector<double> q_deg;
  std::string why;
  double clearance_m{0};  ///< the smallest over the patients' scenes
};

struct DesignCatalog {
  std::string command;  ///< what wrote it
  std::vector<DesignPatient> patients;
  std::vector<CatalogPort> ports;
  std::vector<CatalogTarget> targets;
  /// Docking configurations the planner found but the path rule dropped (id empty).
  std::vector<CatalogTarget> dropped;
  std::vector<CatalogStart> starts;
  DesignSpec spec;  ///< the rules (patients, ports and starts are listed above)
  const DesignPatient* FindPatient(const std::string& name) const;
};

/// The docking point and insertion direction of `port` on a torso box whose top face is at
/// `top_z_m` and whose centre is at `centre_xy_m` (the spec's geometry, see the file comment).
CatalogPort PortOnPatient(const DesignSpec& spec, const DesignPort& port, const Eigen::Vector2d& centre_xy_m,
                          double top_z_m);

/// Plans the catalog (see the file comment): `urdf_path` the robot, `source_root` resolves the
/// scenes. Throws std::runtime_error when a scene cannot be read or has no torso box, or a start
/// or an alignment configuration is not collision-free in some patient's scene; a (patient,
/// port) without any target is kept with none (its counts say so).
DesignCatalog MakeDesignCatalog(const DesignSpec& spec, const std::string& urdf_path,
                                const std::string& source_root, const std::string& command);

/// design.json's text and back (ReadDesignFile checks every field, base/json_fields.h; throws
/// orbed::JsonReadError naming the file and key).
std::string DesignCatalogJson(const DesignCatalog& catalog);
DesignCatalog ReadDesignFile(const std::string& path);

/// The shipped catalog, relative to the source tree.
inline constexpr const char* kDefaultDesignRelativePath = "experiments/setup/design.json";

struct DesignPair {
  std::string start_id, target_id;
  std::vector<double> start_deg, target_deg;
};
struct UserDesign {
  std::string patient, scene;
  std::vector<DesignPair> pairs;  ///< K, in the order every mode runs them
};

/// The user's draw (see the file comment), with base/random.h seeded by user_seed ^ 0xde5196. With
/// `patient` the patient is that one instead of the drawn one (the stream is the same: a user
/// whose drawn patient it is gets the same pairs). Throws std::invalid_argument for K < 1, an
/// unknown patient, or a patient with fewer than K targets.
UserDesign DrawUserDesign(const DesignCatalog& catalog, std::uint64_t user_seed, int k,
                          const std::optional<std::string>& patient = std::nullopt);

/// The user's draw from the design catalog at `design_path` (experiments/setup/design.h); a
/// non-empty `scene_path` fixes the patient to the catalog's patient whose scene file it is (the
/// same file: std::filesystem::equivalent), std::invalid_argument when none is.
UserDesign UserDesignFor(const std::string& design_path, const std::string& scene_path, uint64_t user_seed,
                         int k);

enum class Relation { kSame, kMirror, kMixed };
/// See the file comment; `start_deg` and `target_deg` have at least 6 joints.
Relation BendingRelation(const std::vector<double>& start_deg, const std::vector<double>& target_deg);
const char* RelationName(Relation r);
/// The signs of joints 2, 4, 6 as "+-+" ('0' within 1 deg of 0).
std::string BendingSigns(const std::vector<double>& q_deg);

}  // namespace orbed::setup
