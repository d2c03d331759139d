#pragma once
/// @file
/// The headset's one record of the real robot: the latest valid joint vector q (IIWA_STATUS) and
/// base pose X_WR (ROBOT_STATE), each with whether it has arrived. The shell keeps one; the cores
/// get copies of it.
///
/// Frames: W world, R real robot base. Units: rad, m.
/// Threading: plain data.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace orbed::hmd {

struct RobotState {
  bool have_q{false};
  bool have_X_WR{false};
  Eigen::VectorXd q_rad;
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};

  /// Both are known: the robot can be drawn, ray-cast and aligned to.
  bool known() const { return have_q && have_X_WR; }

  /// The same drawing: both unknown, or both known with exactly equal q and X_WR.
  bool SameAs(const RobotState& other) const {
    if (known() != other.known()) return false;
    if (!known()) return true;
    return q_rad.size() == other.q_rad.size() && q_rad == other.q_rad && X_WR.matrix() == other.X_WR.matrix();
  }
};

}  // namespace orbed::hmd
