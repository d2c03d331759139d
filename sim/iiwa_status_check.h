#pragma once
/// @file
/// The one check a subscriber makes of an IIWA_STATUS before it uses the measured joints against a
/// robot model (orbed-hmd, orbed-guidance): num_joints equals the model's and the array's length,
/// the angles are finite and within the joint limits plus `slack_rad` (the sim clamps to the limits;
/// the slack absorbs rounding).
/// Threading: pure function.

#include <string>

#include <Eigen/Core>
#include <orbed/iiwa_status_t.hpp>

#include "sim/robot_model.h"

namespace orbed::sim {

struct IiwaStatusProblem {
  std::string rejection_class;  ///< "" when the status is usable; else "num_joints", "non_finite", "limits"
  std::string reason;           ///< one line naming the field
};

/// Checks `msg` against `model`; on success sets *q_rad to the measured joints [rad].
IiwaStatusProblem CheckIiwaStatus(const orbed::iiwa_status_t& msg, const RobotModel& model, double slack_rad,
                                  Eigen::VectorXd* q_rad);

}  // namespace orbed::sim
