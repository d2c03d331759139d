#include "hmd_emulator/user_study.h"

#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::hmd {

std::vector<StudyMode> RunStudy(const StudyOptions& o) {
  const std::string root = o.source_dir + "/";
  const sim::RobotModel robot = sim::RobotModel::LoadFile(root + sim::RobotModel::kDefaultUrdfRelativePath);
  const sim::Scene scene = sim::LoadSceneFile(root + sim::kDefaultSceneRelativePath);
  const SlamConfig slam_base =
      LoadSlamConfigFile(o.slam_config_path.empty() ? root + kDefaultSlamConfigRelativePath : o.slam_config_path);
  const UserConfig user_base =
      LoadUserConfigFile(o.user_config_path.empty() ? root + kDefaultUserConfigRelativePath : o.user_config_path);
  const HeadTrajectoryConfig walk =
      LoadHeadTrajectoryFile(o.walk_path.empty() ? root + "hmd_emulator/config/viraal_walk.yaml" : o.walk_path);

  std::vector<std::vector<Eigen::Vector3d>> points;
  for (const auto& q_deg : kStudyConfigurationsDeg) {
    points.push_back(RobotModelPoints(robot, sim::DegToRad(Eigen::Map<const Eigen::VectorXd>(q_deg.data(), 7))));
  }

  std::vector<StudyMode> modes;
  for (int m = 0; m < 2; ++m) {
    StudyMode mode;
    mode.name = m == 0 ? "ar" : "ar_reflective";
    for (int i = 0; i < o.trials_per_mode; ++i) {
      TrialSetup setup;
      setup.X_WR = scene.X_WR;
      setup.p_RQ = points[i % points.size()];
      setup.walk = walk;
      setup.align_waypoint = walk.waypoints.back().name;
      if (m == 1) setup.capture_waypoints = {walk.waypoints.front().name};
      SlamConfig slam = slam_base;
      slam.seed = 100000ULL * (m + 1) + static_cast<std::uint64_t>(i);
      UserConfig person = user_base;
      person.seed = o.base_user_seed + static_cast<std::uint64_t>(i / std::max(1, o.trials_per_user)) +
                    5000ULL * m;
      const EmulatedUser user(person);
      const std::uint64_t trial_seed = 900000ULL * (m + 1) + static_cast<std::uint64_t>(i);
      mode.trials.push_back(RunTrial(setup, slam, user, user.StartPose(scene.X_WR), trial_seed));
    }
    modes.push_back(std::move(mode));
  }
  return modes;
}

}  // namespace orbed::hmd
