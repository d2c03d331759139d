#pragma once
/// @file
/// The set-up study's plan (paper Sec. III-C): distinct target configurations for the same trocar,
/// one per test. Each target docks the tool at the scene's trocar (trocar_ik.h: tool tip at the
/// docking point, tool axis along the insertion direction, within the IK's tolerances and joint-limit
/// margin), is collision-free with an arm clearance (trocar_clearance.h) of at least
/// min_clearance_m, and differs from every earlier target by at least min_separation_deg in some
/// joint other than the last (the largest joint difference over joints 1 .. n−1; the last, the
/// flange's roll, turns the tool about its own axis, which the trocar leaves free and which moves
/// nothing of the arm): a user set up for one target is not already set up for the next. Targets are found
/// one after the other with the trocar IK, its objective replaced outside the separation by the separation's
/// shortfall (so the search is pulled toward distinct configurations) and inside it by the clearance
/// objective. Which distinct configurations the paper's targets were is not published: the separation is a
/// choice of the study (20 deg default).
///
/// A branch (joint_signs, the design catalog's use: experiments/setup/design.h): each target must
/// also have the given sign in the given joints, each at least min_bend_deg from 0 (e.g. joints 2,
/// 4, 6 of the iiwa, whose signs tell its shoulder, elbow and wrist branches apart: (+, −, +) and
/// (−, +, −) are kinematic mirrors). Outside the branch the objective is minus the shortfall, as for
/// the separation, so the search is pulled into the branch; a branch the search cannot enter is
/// reported as a failure like any other.
///
/// Frames: joint angles of the model [rad]; the trocar in the scene's W, converted to R.
/// Threading: pure function (builds its own collision worlds); deterministic for a seed.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::sim {

struct TrocarPlanOptions {
  int num_targets{3};
  double min_separation_deg{20.0};
  double min_clearance_m{0.05};
  std::uint64_t seed{1};
  int starts{48};  ///< IK starts per target
  /// Per joint: +1 or −1 (that sign, at least min_bend_deg from 0) or 0 (free); empty = no branch.
  std::vector<int> joint_signs;
  double min_bend_deg{10.0};
};

/// How far q [rad] is outside the branch: the sum over the signed joints of max(0, min_bend −
/// sign · q_i) [deg]; 0 inside (and for an empty branch).
double BranchShortfallDeg(const Eigen::VectorXd& q_rad, const std::vector<int>& joint_signs,
                          double min_bend_deg);

struct PlannedTarget {
  Eigen::VectorXd q_rad;
  double clearance_m{0};       ///< arm clearance (MakeTrocarArmClearanceFunction)
  double separation_deg{0};    ///< smallest difference (joints 1 .. n−1) to an earlier target (0 first)
  double position_error_m{0};  ///< tool tip to docking point
  double angle_error_deg{0};   ///< tool axis to insertion direction
};

/// The largest |a_i − b_i| [deg] over the first `joints` entries of two joint vectors [rad] (all
/// when joints < 0).
double LargestJointDifferenceDeg(const Eigen::VectorXd& a_rad, const Eigen::VectorXd& b_rad, int joints = -1);

/// Throws std::invalid_argument for options out of range (1..20 targets, separation in [0, 180],
/// clearance >= 0, starts in 1..1000, joint_signs of another size than the model's joints or not in
/// {−1, 0, 1}, min_bend_deg outside [0, 90]) and std::runtime_error naming the first target that could not
/// be found and why (no IK solution, too little clearance, too close to an earlier target, or
/// outside the branch).
/// `model` must carry the scene's tool length (LoadRobotForScene).
std::vector<PlannedTarget> PlanTrocarTargets(const RobotModel& model, const Scene& scene,
                                             const TrocarPlanOptions& options);

}  // namespace orbed::sim
