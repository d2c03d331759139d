#include "hmd_emulator/headset_trial.h"

#include <stdexcept>
#include <utility>

#include "base/hash.h"

namespace orbed::hmd {

std::uint64_t TrialSeed(std::uint64_t seed, const std::string& session_id, std::int32_t index,
                        std::uint64_t purpose) {
  const std::uint64_t h = Fnv1a64(session_id);
  return SplitMix64(SplitMix64(SplitMix64(seed ^ h) ^ static_cast<std::uint64_t>(index)) ^ purpose);
}

void SetRobotAt(const sim::RobotModel& model, const Eigen::VectorXd& q_rad, HeadsetTrialInputs* inputs) {
  inputs->p_RQ = RobotModelPoints(model, q_rad);
  inputs->solids_R = RobotSightSolids(model, q_rad);
}

TrialSetup MakeHeadsetTrialSetup(const HmdConfigSet& config, const HeadsetTrialInputs& inputs) {
  const int placed = static_cast<int>(config.hmd.displays.size());
  if (inputs.num_mirrors < 0 || inputs.num_mirrors > placed) {
    throw std::invalid_argument("headset trial: num_mirrors " + std::to_string(inputs.num_mirrors) +
                                ", the config places " + std::to_string(placed) + " display(s)");
  }
  TrialSetup setup;
  setup.X_WR = inputs.X_WR;
  setup.p_RQ = inputs.p_RQ;
  setup.solids_R = inputs.solids_R;
  setup.walk = config.walk;
  setup.align_waypoint = config.hmd.align_waypoint;
  setup.settle_s = config.hmd.settle_s;
  setup.max_wait_s = config.hmd.max_wait_s;
  setup.max_repeats = config.hmd.max_repeats;
  for (const ScheduledFault& f : config.slam.faults) {
    if (f.AppliesTo(inputs.session_id, inputs.trial_index)) setup.faults.push_back(f.timed);
  }
  setup.intrinsics = geometry::Intrinsics::HoloLensPv();
  setup.p_RL = inputs.p_RL;
  setup.annotation.pointing_std_deg = config.hmd.annotation_pointing_std_deg;
  setup.annotation.dwell_s = config.hmd.annotation_dwell_s;
  setup.annotation.walk_speed_m_per_s = config.hmd.annotation_walk_speed_m_per_s;
  setup.annotation_view_angle_deg = config.hmd.annotation_view_angle_deg;
  setup.collaborator = config.hmd.collaborator;
  if (inputs.collaborator_X_WC_true) setup.collaborator.X_WC_true = inputs.collaborator_X_WC_true;
  if (!inputs.capture_waypoints.empty() &&
      static_cast<int>(inputs.capture_waypoints.size()) != inputs.num_mirrors) {
    throw std::invalid_argument("headset trial: " + std::to_string(inputs.capture_waypoints.size()) +
                                " capture waypoints for " + std::to_string(inputs.num_mirrors) +
                                " display(s)");
  }
  for (int i = 0; i < inputs.num_mirrors; ++i) {
    setup.capture_waypoints.push_back(inputs.capture_waypoints.empty()
                                          ? config.hmd.displays[i].capture_waypoint
                                          : inputs.capture_waypoints[i]);
  }
  return setup;
}

std::vector<Eigen::Vector3d> AnnotationLandmarkPoints(const sim::RobotModel& model, const HmdConfig& hmd,
                                                      const Eigen::VectorXd& q_rad) {
  std::vector<int> links;
  for (const std::string& name : hmd.annotation_landmarks) {
    const int link = model.FindLink(name);
    if (link < 0) {
      throw std::invalid_argument("hmd.annotation_landmarks: the robot model " + model.source_name() +
                                  " has no link '" + name + "'");
    }
    links.push_back(link);
  }
  std::vector<Eigen::Vector3d> p_RL;
  if (links.empty()) return p_RL;
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q_rad);
  for (int link : links) p_RL.push_back(X_RL[link].translation());
  return p_RL;
}

void SetAnnotationFields(const std::vector<AnnotationRay>& annotation, orbed::alignment_trial_t* msg) {
  msg->num_annotation_rays = static_cast<std::int32_t>(annotation.size());
  msg->annotation_landmark.clear();
  msg->annotation_side.clear();
  msg->annotation_origin_W_m.clear();
  msg->annotation_direction_W.clear();
  for (const AnnotationRay& a : annotation) {
    msg->annotation_landmark.push_back(a.landmark);
    msg->annotation_side.push_back(a.hologram ? +orbed::alignment_trial_t::ANNOTATION_VIRTUAL
                                              : +orbed::alignment_trial_t::ANNOTATION_REAL);
    const Eigen::Vector3d& o = a.ray.origin_W;
    const Eigen::Vector3d& u = a.ray.direction_W;
    msg->annotation_origin_W_m.push_back({o.x(), o.y(), o.z()});
    msg->annotation_direction_W.push_back({u.x(), u.y(), u.z()});
  }
}

TrialOutcome RunHeadsetTrial(const HmdConfigSet& config, const HeadsetTrialInputs& inputs,
                             SessionMapCache* cache) {
  const TrialSetup setup = MakeHeadsetTrialSetup(config, inputs);
  const SlamConfig slam = SessionSlamConfig(
      config.slam, TrialSeed(inputs.process_seed, inputs.session_id, 0, kSessionMapPurpose));
  double t0_s = 0;
  SlamModel map =
      SessionMapAtTrial(setup, slam, config.hmd.session_start_m, inputs.trial_index, &t0_s, cache);
  const std::uint64_t trial_seed =
      TrialSeed(inputs.process_seed, inputs.session_id, inputs.trial_index, kTrialSeedPurpose);
  const EmulatedUser user(config.user);
  return RunTrialFrom(setup, std::move(map), t0_s, user, inputs.X_WV_start, trial_seed);
}

}  // namespace orbed::hmd
