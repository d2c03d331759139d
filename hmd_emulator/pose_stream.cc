#include "hmd_emulator/pose_stream.h"

#include "hmd_emulator/gaze.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::hmd {

static_assert(static_cast<int>(TrackingState::kTracking) == orbed::hmd_pose_t::TRACKING &&
                  static_cast<int>(TrackingState::kLimited) == orbed::hmd_pose_t::LIMITED &&
                  static_cast<int>(TrackingState::kLost) == orbed::hmd_pose_t::LOST &&
                  static_cast<int>(TrackingState::kRelocalized) == orbed::hmd_pose_t::RELOCALIZED,
              "TrackingState must number as hmd_pose_t's constants");

PoseStream::PoseStream(const HmdConfigSet& config, const sim::Scene& scene, const sim::RobotModel& robot)
    : hmd_name_(config.hmd.name),
      max_gaze_distance_m_(config.hmd.max_gaze_distance_m),
      trajectory_(config.walk),
      slam_(config.slam) {
  scene_objects_.AddSceneObjects(scene);
  robot_geometry_.AddRobot(robot, render::BodyKind::kRealRobot);
}

void PoseStream::ScheduleFault(double t_s, const ForcedFault& fault) { scheduled_.push_back({t_s, fault}); }

PoseStream::Poses PoseStream::Step(double t_s, int64_t utime) {
  t_s_ = t_s;
  if (!scheduled_.empty() && scheduled_.front().at_s <= t_s && !slam_.forcing()) {
    slam_.Force(scheduled_.front().fault);
    scheduled_.pop_front();
  }
  const SlamSample s = slam_.Step(trajectory_.X_WH(t_s), t_s);
  Poses poses;
  orbed::hmd_pose_t& est = poses.estimate;
  est.utime = utime;
  est.seq = s.seq;
  est.hmd_name = hmd_name_;
  est.X_WH = ToPose(s.X_WH_est);
  est.X_WC = ToPose(s.X_WC_est);
  est.tracking_state = static_cast<int8_t>(s.state);
  poses.truth = est;
  poses.truth.X_WH = ToPose(s.X_WH_true);
  poses.truth.X_WC = ToPose(s.X_WC_true);
  sample_ = s;
  sample_utime_ = utime;
  have_sample_ = true;
  return poses;
}

std::optional<orbed::gaze_ray_t> PoseStream::Gaze(const RobotState& robot) {
  if (!have_sample_) return std::nullopt;
  const SlamSample& s = sample_;
  const Eigen::Vector3d p_true = s.X_WH_true.translation(), d_true = s.X_WH_true.linear().col(2);
  RayHit hit = CastRay(scene_objects_, p_true, d_true, render::kRealWorld, max_gaze_distance_m_);
  if (robot.known()) {
    robot_geometry_.PoseRobot(0, robot.q_rad, robot.X_WR);
    const RayHit r = CastRay(robot_geometry_, p_true, d_true, render::kRealWorld, max_gaze_distance_m_);
    if (r.hit && r.distance_m < hit.distance_m) hit = r;
  }
  const Eigen::Vector3d p_est = s.X_WH_est.translation(), d_est = s.X_WH_est.linear().col(2);
  orbed::gaze_ray_t msg{};
  msg.utime = sample_utime_;
  msg.hmd_name = hmd_name_;
  FromVector3(p_est, msg.origin_W_m);
  FromVector3(d_est, msg.direction_W);
  msg.valid = hit.hit;
  if (hit.hit) {
    FromVector3(p_est + hit.distance_m * d_est, msg.hit_W_m);
    msg.hit_distance_m = hit.distance_m;
    msg.hit_body = hit.body_name;
  }
  return msg;
}

}  // namespace orbed::hmd
