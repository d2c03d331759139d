#pragma once
/// @file
/// Errors of a ViRAAl alignment against the truth, without a bus: where the virtual robot V (base
/// pose X_WV chosen by the user) puts points of the robot compared with where the real robot R
/// (true base pose X_WR) has them, at the joint configuration q of the trial.
///
/// Frames (docs/design.md): W the OR world, R the real robot base, V the virtual robot base (the same
/// model, so a point fixed on link L is p_RQ = X_RL(q)·p_LQ on the real robot and p_VQ = p_RQ on the
/// virtual one). A point Q of the robot is at p_WQ_real = X_WR·p_RQ and p_WQ_virtual = X_WV·p_RQ.
///
/// Measures (all in SI here; the results file converts to mm / deg):
///   - rotation_rad: geodesic angle of R_WR^T·R_WV, in [0, π].
///   - base_translation_m: ‖p_WV − p_WR‖, the error at the base origin. An angular error moves
///     points of the arm far more than the base, so this alone understates what a user sees.
///   - centroid_translation_m: ‖p_WC_virtual − p_WC_real‖ with C the robot's centroid at q, the
///     mean of the origins of the links from the base up to and including the flange (for the iiwa
///     7: iiwa_link_0 … iiwa_link_7 and iiwa_link_ee, 9 points). This is the "translation error" of
///     the results file.
///   - flange_translation_m: the same at the flange origin F.
///   - landmark pairs: p_W_real / p_W_virtual of each landmark (a link origin, e.g. elbow
///     iiwa_link_4, wrist iiwa_link_6, flange iiwa_link_ee), the input of the paper's Table 1
///     misalignment (geometry/misalignment.h), which orbed-registration evaluates.
///
/// For a session's mean X_WV there is no single q: EvaluateOverConfigurations averages the point
/// errors over the session's configurations and concatenates their landmark pairs.
///
/// The viewer frame S (ViewerFrame), for the per-axis errors as the person saw them: origin at the
/// eye E (where the person stood when aligning; exchange.h AlignmentViewpoint takes it from the
/// annotation's gaze rays), z the line of sight from E to T, the centroid of the real robot's
/// landmarks at the trial's q (X_WR·p_RL, the truth); x horizontal (perpendicular to W's z, which
/// points up), to the viewer's right; y = z × x, downward in the vertical plane of the line of
/// sight. x right, y down, z away from the eye: the camera convention the paper uses for its
/// displays (Sec. II). An error along z is depth along the line of sight. Only if the line of sight
/// is vertical (within 1e-9 rad) is x instead W's x.
///
/// Threading: pure functions; RobotPointSet is a value. Reentrant.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "sim/robot_model.h"

namespace orbed::viraal {

/// The robot points used to measure an alignment at one configuration, in the base frame R [m].
struct RobotPoints {
  Eigen::Vector3d p_RC{Eigen::Vector3d::Zero()};  ///< centroid (mean of link origins, base .. flange)
  Eigen::Vector3d p_RF{Eigen::Vector3d::Zero()};  ///< flange origin
  std::vector<Eigen::Vector3d> p_RL;              ///< landmark origins, in landmark order
};

/// Which links carry the landmarks, resolved against a model.
class RobotPointSet {
 public:
  /// Throws std::invalid_argument naming a landmark link the model does not have, or when fewer
  /// than one landmark is given.
  RobotPointSet(const orbed::sim::RobotModel& model, const std::vector<std::string>& landmark_links);

  const std::vector<std::string>& landmark_names() const { return landmark_names_; }
  /// Forward kinematics at q [rad] (num_joints values; std::invalid_argument otherwise).
  RobotPoints At(const Eigen::VectorXd& q_rad) const;

 private:
  const orbed::sim::RobotModel* model_;
  std::vector<std::string> landmark_names_;
  std::vector<int> landmark_indices_;
  std::vector<int> centroid_indices_;
};

struct AlignmentError {
  double rotation_rad{0};
  double base_translation_m{0};
  double centroid_translation_m{0};
  double flange_translation_m{0};
  /// One pair per landmark (and per configuration for EvaluateOverConfigurations), in W [m].
  std::vector<Eigen::Vector3d> p_W_real;
  std::vector<Eigen::Vector3d> p_W_virtual;
  /// The same landmarks as the user annotated them (triangulated gaze rays, in the headset's map)
  /// [m]; empty when nobody annotated (see exchange.h).
  std::vector<Eigen::Vector3d> p_W_real_annotated;
  std::vector<Eigen::Vector3d> p_W_virtual_annotated;
  /// With annotated pairs: false when the virtual side was placed by the pose itself rather than
  /// annotated (a session mean, which no hologram ever showed: exchange.h MeanError).
  bool virtual_annotated{true};
  /// The viewer frame of each landmark pair, R_WS (ViewerFrame), in p_W_real's order; empty when no
  /// eye is known (nobody annotated: WithViewer, exchange.h MeanError).
  std::vector<Eigen::Matrix3d> R_WS;
  /// The eye a trial's frames were made from, in W [m] (WithViewer); unset for a mean.
  std::optional<Eigen::Vector3d> p_WE;
};

/// Geodesic angle between two rotations [rad], in [0, π]: the angle of R_a^T·R_b.
double RotationAngle(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);

/// The viewer frame's orientation R_WS for an eye at p_WE looking at p_WT (both in W [m]); see the
/// file comment. Throws std::invalid_argument when the two points are less than 1 mm apart.
Eigen::Matrix3d ViewerFrame(const Eigen::Vector3d& p_WE, const Eigen::Vector3d& p_WT);

/// `error` (one trial's) with its viewer frames: every pair's R_WS = ViewerFrame(p_WE, centroid of
/// error.p_W_real), and p_WE kept.
AlignmentError WithViewer(AlignmentError error, const Eigen::Vector3d& p_WE);

/// Per-axis errors of landmark pairs in their viewer frames: mean over the pairs k of
/// |R_WS[k]ᵀ·(p_W_virtual[k] − p_W_real[k])| per axis of S [m]. Throws std::invalid_argument when
/// the three lists' sizes differ or are 0.
Eigen::Vector3d ViewerAxesError(const std::vector<Eigen::Vector3d>& p_W_real,
                                const std::vector<Eigen::Vector3d>& p_W_virtual,
                                const std::vector<Eigen::Matrix3d>& R_WS);

/// The errors of one trial (X_WV at q) against the truth X_WR.
AlignmentError EvaluateAlignment(const Eigen::Isometry3d& X_WR, const Eigen::Isometry3d& X_WV,
                                 const RobotPoints& points);

/// The errors of one pose (a session mean) over several configurations: point errors averaged over
/// `points` (one entry per configuration), landmark pairs of all configurations concatenated.
/// Throws std::invalid_argument when `points` is empty.
AlignmentError EvaluateOverConfigurations(const Eigen::Isometry3d& X_WR, const Eigen::Isometry3d& X_WV,
                                          const std::vector<RobotPoints>& points);

}  // namespace orbed::viraal
