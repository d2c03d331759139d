#include "experiments/viraal/metrics.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace orbed::viraal {

RobotPointSet::RobotPointSet(const orbed::sim::RobotModel& model,
                             const std::vector<std::string>& landmark_links)
    : model_(&model), landmark_names_(landmark_links) {
  if (landmark_links.empty()) throw std::invalid_argument("landmarks: at least one link is needed");
  for (const std::string& name : landmark_links) {
    const int index = model.FindLink(name);
    if (index < 0) {
      throw std::invalid_argument("landmarks: the robot model " + model.source_name() + " has no link '" +
                                  name + "'");
    }
    landmark_indices_.push_back(index);
  }
  // Links are in topological order: the base comes first, the tool after the flange.
  const int last = model.flange_link() >= 0 ? model.flange_link() : model.num_links() - 1;
  for (int i = 0; i <= last; ++i) centroid_indices_.push_back(i);
}

RobotPoints RobotPointSet::At(const Eigen::VectorXd& q_rad) const {
  const std::vector<Eigen::Isometry3d> X_RL = model_->CalcLinkPoses(q_rad);
  RobotPoints points;
  for (int i : centroid_indices_) points.p_RC += X_RL[i].translation();
  points.p_RC /= static_cast<double>(centroid_indices_.size());
  points.p_RF = model_->CalcFlangePose(q_rad).translation();
  for (int i : landmark_indices_) points.p_RL.push_back(X_RL[i].translation());
  return points;
}

double RotationAngle(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  // Through the quaternion: 2·atan2(|v|, |w|) keeps full precision near 0 and near π, unlike
  // acos((trace − 1) / 2).
  const Eigen::Quaterniond q(R_a.transpose() * R_b);
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

Eigen::Matrix3d ViewerFrame(const Eigen::Vector3d& p_WE, const Eigen::Vector3d& p_WT) {
  const Eigen::Vector3d line_of_sight = p_WT - p_WE;
  if (!(line_of_sight.norm() >= 1e-3))
    throw std::invalid_argument("ViewerFrame: the eye and the point looked at are less than 1 mm apart");
  const Eigen::Vector3d z = line_of_sight.normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());  // horizontal, to the right of the line of sight
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX();      // looking straight up or down
  x.normalize();
  Eigen::Matrix3d R_WS;
  R_WS.col(0) = x;
  R_WS.col(1) = z.cross(x);
  R_WS.col(2) = z;
  return R_WS;
}

AlignmentError WithViewer(AlignmentError error, const Eigen::Vector3d& p_WE) {
  if (error.p_W_real.empty()) throw std::invalid_argument("WithViewer: no landmark pairs");
  Eigen::Vector3d p_WT = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : error.p_W_real) p_WT += p;
  p_WT /= static_cast<double>(error.p_W_real.size());
  error.R_WS.assign(error.p_W_real.size(), ViewerFrame(p_WE, p_WT));
  error.p_WE = p_WE;
  return error;
}

Eigen::Vector3d ViewerAxesError(const std::vector<Eigen::Vector3d>& p_W_real,
                                const std::vector<Eigen::Vector3d>& p_W_virtual,
                                const std::vector<Eigen::Matrix3d>& R_WS) {
  if (p_W_real.empty() || p_W_real.size() != p_W_virtual.size() || p_W_real.size() != R_WS.size())
    throw std::invalid_argument("ViewerAxesError: " + std::to_string(p_W_real.size()) + " real, " +
                                std::to_string(p_W_virtual.size()) + " virtual landmarks, " +
                                std::to_string(R_WS.size()) + " frames");
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < p_W_real.size(); ++k)
    sum += (R_WS[k].transpose() * (p_W_virtual[k] - p_W_real[k])).cwiseAbs();
  return sum / static_cast<double>(p_W_real.size());
}

AlignmentError EvaluateAlignment(const Eigen::Isometry3d& X_WR, const Eigen::Isometry3d& X_WV,
                                 const RobotPoints& points) {
  return EvaluateOverConfigurations(X_WR, X_WV, {points});
}

AlignmentError EvaluateOverConfigurations(const Eigen::Isometry3d& X_WR, const Eigen::Isometry3d& X_WV,
                                          const std::vector<RobotPoints>& points) {
  if (points.empty()) throw std::invalid_argument("EvaluateOverConfigurations: no configurations");
  AlignmentError error;
  error.rotation_rad = RotationAngle(X_WR.linear(), X_WV.linear());
  error.base_translation_m = (X_WV.translation() - X_WR.translation()).norm();
  // Where the same robot point lands on the real and on the virtual robot.
  const auto gap = [&](const Eigen::Vector3d& p_RQ) { return (X_WV * p_RQ - X_WR * p_RQ).norm(); };
  for (const RobotPoints& at_q : points) {
    error.centroid_translation_m += gap(at_q.p_RC);
    error.flange_translation_m += gap(at_q.p_RF);
    for (const Eigen::Vector3d& p_RL : at_q.p_RL) {
      error.p_W_real.push_back(X_WR * p_RL);
      error.p_W_virtual.push_back(X_WV * p_RL);
    }
  }
  error.centroid_translation_m /= static_cast<double>(points.size());
  error.flange_translation_m /= static_cast<double>(points.size());
  return error;
}

}  // namespace orbed::viraal
