#include "hmd_emulator/user_study.h"

#include <cstdio>
#include <functional>

#include "geometry/se3_mean.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

// The base-origin errors of the SE(3) means of consecutive triples of trials.
std::vector<double> TripleMeanErrors(const std::vector<TrialOutcome>& trials, const Eigen::Vector3d& p_WR) {
  std::vector<double> errors;
  for (std::size_t g = 0; g + 3 <= trials.size(); g += 3) {
    std::vector<Eigen::Quaterniond> q;
    std::vector<Eigen::Vector3d> p;
    for (std::size_t k = g; k < g + 3; ++k) {
      q.emplace_back(trials[k].alignment.X_WV.linear());
      p.push_back(trials[k].alignment.X_WV.translation());
    }
    // Base origin averaging (eq. 3); rotation errors are ~0.1 deg, so the centroid matters little.
    const geometry::Se3MeanResult r = geometry::ComputeSe3Mean(q, p, geometry::Se3MeanOptions{});
    if (r.valid) errors.push_back((r.p_WV_mean - p_WR).norm());
  }
  return errors;
}

std::vector<double> Series(const StudyMode& mode, const std::function<double(const TrialOutcome&)>& value) {
  std::vector<double> v;
  for (const auto& t : mode.trials) v.push_back(value(t));
  return v;
}

void AppendLine(std::string* out, const char* label, const std::vector<double>& v, double scale) {
  std::vector<double> s;
  for (double x : v) s.push_back(x * scale);
  char line[200];
  std::snprintf(line, sizeof(line), "  %-34s mean %7.2f  std %7.2f  median %7.2f  p90 %7.2f\n", label,
                stats::Mean(s), stats::StdDev(s), stats::Median(s), stats::Quantile(s, 0.9));
  *out += line;
}

}  // namespace

std::vector<StudyMode> RunStudy(const StudyOptions& o) {
  const std::string root = o.source_dir + "/";
  const sim::Scene scene = sim::LoadSceneFile(root + sim::kDefaultSceneRelativePath);
  const sim::RobotModel robot =
      sim::LoadRobotForScene(root + sim::RobotModel::kDefaultUrdfRelativePath, scene);
  const SlamConfig slam_base = LoadSlamConfigFile(
      o.slam_config_path.empty() ? root + kDefaultSlamConfigRelativePath : o.slam_config_path);
  const UserConfig user_base = LoadUserConfigFile(
      o.user_config_path.empty() ? root + kDefaultUserConfigRelativePath : o.user_config_path);
  const HeadTrajectoryConfig walk = LoadHeadTrajectoryFile(
      o.walk_path.empty() ? root + "hmd_emulator/config/viraal_walk.yaml" : o.walk_path);
  const std::vector<std::string> display_waypoints =
      o.display_waypoints.empty() ? std::vector<std::string>{walk.waypoints.front().name}
                                  : o.display_waypoints;

  std::vector<std::vector<Eigen::Vector3d>> points;
  for (const auto& q_deg : kStudyConfigurationsDeg) {
    points.push_back(
        RobotModelPoints(robot, sim::DegToRad(Eigen::Map<const Eigen::VectorXd>(q_deg.data(), 7))));
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
      if (m == 1) setup.capture_waypoints = display_waypoints;
      // The same seeds in both modes: paired trials (see the file comment).
      SlamConfig slam = slam_base;
      slam.seed = 100000ULL + static_cast<std::uint64_t>(i);
      UserConfig person = user_base;
      person.seed = o.base_user_seed + static_cast<std::uint64_t>(i / std::max(1, o.trials_per_user));
      const EmulatedUser user(person);
      const std::uint64_t trial_seed = 900000ULL + static_cast<std::uint64_t>(i);
      mode.trials.push_back(RunTrial(setup, slam, user, user.StartPose(scene.X_WR), trial_seed));
    }
    mode.mean_base_error_m = TripleMeanErrors(mode.trials, scene.X_WR.translation());
    modes.push_back(std::move(mode));
  }
  return modes;
}

StudyComparison CompareModes(const StudyMode& with, const StudyMode& without) {
  auto error = [](const TrialOutcome& t) { return t.registration.translation_error_m; };
  const std::vector<double> x = Series(with, error), y = Series(without, error);
  StudyComparison c;
  c.mann_whitney = stats::MannWhitneyU(x, y);
  c.signed_rank = stats::WilcoxonSignedRank(x, y);
  return c;
}

std::string FormatStudyReport(const std::vector<StudyMode>& modes) {
  std::string out;
  for (const StudyMode& m : modes) {
    char head[120];
    std::snprintf(head, sizeof(head), "%s (%zu trials)\n", m.name.c_str(), m.trials.size());
    out += head;
    AppendLine(&out, "registration, centroid [mm]",
               Series(m, [](const TrialOutcome& t) { return t.registration.translation_error_m; }), 1e3);
    AppendLine(&out, "registration, base origin [mm]",
               Series(m, [](const TrialOutcome& t) { return t.registration.base_translation_error_m; }), 1e3);
    AppendLine(&out, "registration, rotation [deg]",
               Series(m, [](const TrialOutcome& t) { return t.registration.rotation_error_deg; }), 1.0);
    AppendLine(&out, "augmentation, centroid [mm]",
               Series(m, [](const TrialOutcome& t) { return t.augmentation.translation_error_m; }), 1e3);
    AppendLine(&out, "augmentation, along the ray [mm]",
               Series(m, [](const TrialOutcome& t) { return t.augmentation.along_ray_m; }), 1e3);
    AppendLine(&out, "augmentation, across the ray [mm]",
               Series(m, [](const TrialOutcome& t) { return t.augmentation.lateral_m; }), 1e3);
    AppendLine(&out, "augmentation, mean point [mm]",
               Series(m, [](const TrialOutcome& t) { return t.augmentation.mean_point_error_m; }), 1e3);
    AppendLine(&out, "nudges", Series(m, [](const TrialOutcome& t) { return t.alignment.nudges; }), 1.0);
    AppendLine(&out, "duration [s]", Series(m, [](const TrialOutcome& t) { return t.alignment.duration_s; }),
               1.0);
    AppendLine(&out, "SE(3) mean of 3, base origin [mm]", m.mean_base_error_m, 1e3);
  }
  if (modes.size() >= 2) {
    const StudyComparison c = CompareModes(modes.back(), modes.front());
    char line[300];
    std::snprintf(line, sizeof(line),
                  "Mann-Whitney (registration error, %s < %s): U = %.1f, z = %.2f, p = %.3g\n",
                  modes.back().name.c_str(), modes.front().name.c_str(), c.mann_whitney.u_x, c.mann_whitney.z,
                  c.mann_whitney.p_x_less);
    out += line;
    if (c.signed_rank.valid) {
      std::snprintf(
          line, sizeof(line),
          "Wilcoxon signed-rank (paired trials, %s < %s): W+ = %.1f of %d pairs, z = %.2f, p = %.3g\n",
          modes.back().name.c_str(), modes.front().name.c_str(), c.signed_rank.w_plus, c.signed_rank.n,
          c.signed_rank.z, c.signed_rank.p_x_less);
      out += line;
    }
  }
  out += "paper Table 1: ar 30.2 +- 23.9 mm, ar_reflective 16.5 +- 11.0 mm, SE(3) mean 11.3 mm\n";
  return out;
}

}  // namespace orbed::hmd
