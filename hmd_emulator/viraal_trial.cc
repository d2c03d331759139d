#include "hmd_emulator/viraal_trial.h"

#include <cmath>
#include <stdexcept>

namespace orbed::hmd {

TrialOutcome RunTrial(const TrialSetup& setup, const SlamConfig& slam, const EmulatedUser& user,
                      const Eigen::Isometry3d& X_WV_start, std::uint64_t trial_seed) {
  const HeadTrajectory trajectory(setup.walk);
  auto waypoint = [&trajectory](const std::string& name) {
    const int i = trajectory.FindWaypoint(name);
    if (i < 0) throw std::invalid_argument("RunTrial: the walk has no waypoint '" + name + "'");
    return i;
  };
  const double t_align = trajectory.ArrivalTime(waypoint(setup.align_waypoint)) + setup.settle_s;
  std::vector<double> t_capture;
  for (const auto& name : setup.capture_waypoints)
    t_capture.push_back(trajectory.ArrivalTime(waypoint(name)));

  TrialOutcome out;
  SlamModel model(slam);
  const double dt = 1.0 / slam.rate_hz;
  std::vector<bool> captured(t_capture.size(), false);
  out.at_capture.resize(t_capture.size());
  const long long steps = static_cast<long long>(std::ceil(t_align / dt - 1e-9));
  for (long long k = 0; k <= steps; ++k) {
    const double t = std::min(k * dt, t_align);
    const SlamSample s = model.Step(trajectory.X_WH(t), t);
    if (s.state == TrackingState::kRelocalized) ++out.relocalizations;
    for (std::size_t j = 0; j < t_capture.size(); ++j) {
      if (!captured[j] && t >= t_capture[j] - 1e-9) {
        out.at_capture[j] = s;
        captured[j] = true;
      }
    }
    out.at_alignment = s;
  }
  // A person waits for the headset to track again before aligning (holograms swim or freeze while
  // tracking is limited or lost): keep standing until TRACKING, for at most max_wait_s.
  const Eigen::Isometry3d X_WH_stand = trajectory.X_WH(t_align);
  for (double t = t_align + dt;
       out.at_alignment.state != TrackingState::kTracking && t <= t_align + setup.max_wait_s; t += dt) {
    out.at_alignment = model.Step(X_WH_stand, t);
    if (out.at_alignment.state == TrackingState::kRelocalized) ++out.relocalizations;
  }

  ViewingContext ctx;
  ctx.X_WR = setup.X_WR;
  ctx.X_WH_true = out.at_alignment.X_WH_true;
  ctx.X_WH_est = out.at_alignment.X_WH_est;
  for (const auto& cap : out.at_capture) {
    ReflectiveDisplayView view;
    view.intrinsics = setup.intrinsics;
    view.X_WC_true = cap.X_WC_true;
    view.X_WC_est = cap.X_WC_est;
    ctx.displays.push_back(view);
  }
  out.alignment = user.Align(ctx, setup.p_RQ, X_WV_start, trial_seed);
  const Eigen::Vector3d p_W_eye = ctx.X_WH_true.translation();
  out.registration = EvaluatePose(out.alignment.X_WV, setup.X_WR, setup.p_RQ, p_W_eye);
  out.augmentation = EvaluatePose(ApparentPose(ctx.X_WH_true, ctx.X_WH_est, out.alignment.X_WV), setup.X_WR,
                                  setup.p_RQ, p_W_eye);
  return out;
}

}  // namespace orbed::hmd
