#include "sim/trocar_ik.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <Eigen/SVD>

namespace orbed::sim {
namespace {

// The 5-row task: position error (3) and the axis error projected on two directions normal to the
// current tool axis (2). Returns the error and the matching Jacobian rows.
struct Task {
  Eigen::Matrix<double, 5, 1> e;
  Eigen::MatrixXd J;  // 5 x n
  double position_error_m{0};
  double angle_error_rad{0};
};

Task EvalTask(const RobotModel& model, const TrocarIkTarget& target, const Eigen::VectorXd& q,
              std::vector<Eigen::Isometry3d>* X_RL) {
  model.CalcLinkPoses(q, X_RL);
  const Eigen::Isometry3d& X_RT = (*X_RL)[model.tool_tip_link()];
  const Eigen::MatrixXd J6 = model.CalcJacobian(*X_RL, model.tool_tip_link());
  const Eigen::Vector3d z = X_RT.linear().col(2);
  // Orthonormal u1, u2 normal to z.
  const Eigen::Vector3d helper = std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u1 = z.cross(helper).normalized();
  const Eigen::Vector3d u2 = z.cross(u1);
  // Rotating z by a small w changes it by w x z; the rotation that takes z to the target axis a is
  // about z x a with angle atan2(|z x a|, z.a).
  const Eigen::Vector3d zxa = z.cross(target.axis_R);
  const double s = zxa.norm();
  const double angle = std::atan2(s, z.dot(target.axis_R));
  const Eigen::Vector3d w_err = s > 1e-12 ? Eigen::Vector3d(zxa * (angle / s)) : Eigen::Vector3d::Zero();
  Task t;
  t.e.head<3>() = target.p_RT - X_RT.translation();
  t.e[3] = u1.dot(w_err);
  t.e[4] = u2.dot(w_err);
  t.J.resize(5, model.num_joints());
  t.J.topRows<3>() = J6.bottomRows<3>();
  t.J.row(3) = u1.transpose() * J6.topRows<3>();
  t.J.row(4) = u2.transpose() * J6.topRows<3>();
  t.position_error_m = t.e.head<3>().norm();
  t.angle_error_rad = angle;
  return t;
}

Eigen::VectorXd Clamp(const Eigen::VectorXd& q, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi) {
  return q.cwiseMax(lo).cwiseMin(hi);
}

// Damped least squares from q onto the task, within [lo, hi]. Returns true on convergence.
bool Project(const RobotModel& model, const TrocarIkTarget& target, const TrocarIkOptions& opt,
             const Eigen::VectorXd& lo, const Eigen::VectorXd& hi, Eigen::VectorXd* q,
             std::vector<Eigen::Isometry3d>* X_RL) {
  const int n = model.num_joints();
  double lambda = 1e-2;
  Task t = EvalTask(model, target, *q, X_RL);
  for (int it = 0; it < opt.max_iterations; ++it) {
    if (t.position_error_m < opt.position_tolerance_m && t.angle_error_rad < opt.angle_tolerance_rad)
      return true;
    const Eigen::Matrix<double, 5, 5> A =
        t.J * t.J.transpose() + lambda * lambda * Eigen::Matrix<double, 5, 5>::Identity();
    Eigen::VectorXd dq = t.J.transpose() * A.ldlt().solve(t.e);
    const double norm = dq.norm();
    if (norm > 0.3) dq *= 0.3 / norm;
    const Eigen::VectorXd q_new = Clamp(*q + dq, lo, hi);
    Task t_new = EvalTask(model, target, q_new, X_RL);
    if (t_new.e.norm() < t.e.norm()) {
      *q = q_new;
      t = t_new;
      lambda = std::max(1e-4, lambda * 0.5);
    } else {
      lambda *= 4.0;
      if (lambda > 10.0) return false;
    }
  }
  (void)n;
  return t.position_error_m < opt.position_tolerance_m && t.angle_error_rad < opt.angle_tolerance_rad;
}

// Two unit vectors spanning the null space of the task Jacobian at q.
Eigen::MatrixXd NullSpace(const RobotModel& model, const TrocarIkTarget& target, const Eigen::VectorXd& q,
                          std::vector<Eigen::Isometry3d>* X_RL) {
  const Task t = EvalTask(model, target, q, X_RL);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(t.J, Eigen::ComputeFullV);
  const int n = model.num_joints();
  return svd.matrixV().rightCols(n - 5);
}

}  // namespace

void TrocarIkResiduals(const RobotModel& model, const TrocarIkTarget& target, const Eigen::VectorXd& q_rad,
                       double* position_error_m, double* angle_error_rad) {
  std::vector<Eigen::Isometry3d> X_RL;
  const Task t = EvalTask(model, target, q_rad, &X_RL);
  *position_error_m = t.position_error_m;
  *angle_error_rad = t.angle_error_rad;
}

TrocarIkResult SolveTrocarIk(const RobotModel& model, const TrocarIkTarget& target_in,
                             const TrocarIkOptions& opt, const ClearanceFunction& clearance) {
  if (!target_in.p_RT.allFinite() || !target_in.axis_R.allFinite() ||
      std::abs(target_in.axis_R.norm() - 1.0) > 1e-3) {
    throw std::invalid_argument("SolveTrocarIk: the target needs a finite position and a unit axis");
  }
  if (model.num_joints() < 6) throw std::invalid_argument("SolveTrocarIk: needs at least 6 joints");
  TrocarIkTarget target = target_in;
  target.axis_R.normalize();
  const int n = model.num_joints();
  const Eigen::VectorXd lo = model.lower_limits_rad().array() + opt.limit_margin_rad;
  const Eigen::VectorXd hi = model.upper_limits_rad().array() - opt.limit_margin_rad;
  auto score = [&](const Eigen::VectorXd& q) { return clearance ? clearance(q) : 0.0; };

  std::mt19937_64 rng(opt.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Isometry3d> X_RL;
  struct Candidate {
    Eigen::VectorXd q;
    double clearance;
  };
  std::vector<Candidate> candidates;
  TrocarIkResult result;
  for (int s = 0; s < opt.num_seeds; ++s) {
    Eigen::VectorXd q(n);
    for (int i = 0; i < n; ++i) q[i] = lo[i] + (hi[i] - lo[i]) * unit(rng);
    ++result.seeds_tried;
    if (!Project(model, target, opt, lo, hi, &q, &X_RL)) continue;
    ++result.seeds_converged;
    candidates.push_back({q, score(q)});
  }
  if (candidates.empty()) {
    result.message = "no start of " + std::to_string(opt.num_seeds) +
                     " converged onto the trocar pose within the joint limits (unreachable target?)";
    return result;
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.clearance > b.clearance; });
  // Keep distinct solutions for refinement.
  std::vector<Candidate> distinct;
  for (const auto& c : candidates) {
    bool dup = false;
    for (const auto& d : distinct) dup = dup || (c.q - d.q).norm() < 0.05;
    if (!dup) distinct.push_back(c);
    if (static_cast<int>(distinct.size()) >= opt.refine_best) break;
  }

  // Pattern search in the null space, re-projected onto the task.
  for (auto& c : distinct) {
    double step = 0.2;
    int steps = 0;
    while (step > 2e-3 && steps < opt.max_refine_steps) {
      const Eigen::MatrixXd N = NullSpace(model, target, c.q, &X_RL);
      bool improved = false;
      for (int k = 0; k < N.cols() && !improved; ++k) {
        for (double sign : {1.0, -1.0}) {
          ++steps;
          Eigen::VectorXd q = Clamp(c.q + sign * step * N.col(k), lo, hi);
          if (!Project(model, target, opt, lo, hi, &q, &X_RL)) continue;
          const double value = score(q);
          if (value > c.clearance + 1e-7) {
            c.q = q;
            c.clearance = value;
            improved = true;
            break;
          }
        }
      }
      if (!improved) step *= 0.5;
    }
  }
  const Candidate& best =
      *std::max_element(distinct.begin(), distinct.end(),
                        [](const Candidate& a, const Candidate& b) { return a.clearance < b.clearance; });
  result.q_rad = best.q;
  result.clearance_m = best.clearance;
  TrocarIkResiduals(model, target, best.q, &result.position_error_m, &result.angle_error_rad);
  std::ostringstream os;
  if (!(best.clearance > opt.min_clearance_m)) {
    os << "reached the trocar pose from " << result.seeds_converged << " of " << result.seeds_tried
       << " starts, but the best clearance " << best.clearance << " m is not above " << opt.min_clearance_m
       << " m (every solution collides)";
    result.message = os.str();
    return result;
  }
  result.success = true;
  os << "clearance objective " << best.clearance << " m; " << result.seeds_converged << " of "
     << result.seeds_tried << " starts converged";
  result.message = os.str();
  return result;
}

}  // namespace orbed::sim
