// The emulated ViRAAl user. Oracles: the truth (a perfect perceiver with perfect tracking ends at
// X_WR), the geometry of the viewing ray, and the statistical claims of the paper's Table 1 tested
// with the rank test of stats.h (whose own oracles are hand computations).
#include "hmd_emulator/user_model.h"

#include <cmath>
#include <cstdlib>
#include <set>
#include <string>
#include "base/source_paths.h"

#include <gtest/gtest.h>

#include "base/stats.h"
#include "base/yaml_fields.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

sim::RobotModel Robot() {
  return sim::RobotModel::LoadFile(orbed::SourceDir() + "/" + sim::RobotModel::kDefaultUrdfRelativePath);
}

TEST(RobotModelPoints, OnTheUprightArm) {
  const sim::RobotModel robot = Robot();
  const std::vector<Eigen::Vector3d> p = RobotModelPoints(robot, Eigen::VectorXd::Zero(7));
  ASSERT_GE(p.size(), 15u);
  double z_max = 0;
  for (const auto& x : p) {
    // Upright (q = 0): every axis point within the links' 0.2 m of the vertical axis, above the base.
    EXPECT_LT(std::hypot(x.x(), x.y()), 0.2);
    EXPECT_GE(x.z(), -1e-9);
    z_max = std::max(z_max, x.z());
  }
  // The flange is at d1 + d3 + d5 + d7 = 0.34 + 0.4 + 0.4 + 0.126 = 1.266 m (DH), the tool beyond.
  EXPECT_GE(z_max, 1.266 - 1e-6);
  EXPECT_THROW(RobotModelPoints(robot, Eigen::VectorXd::Zero(3)), std::invalid_argument);
}

// A person who perceives perfectly, with perfect tracking, ends where the real robot is.
TEST(EmulatedUser, PerfectPerceiverFindsTheTruth) {
  const sim::RobotModel robot = Robot();
  const std::vector<Eigen::Vector3d> p_RQ =
      RobotModelPoints(robot, sim::DegToRad((Eigen::VectorXd(7) << 0, 20, 0, -70, 0, 60, 0).finished()));
  UserConfig c;
  c.lateral_noise_arcmin = c.lateral_bias_arcmin = 0;
  c.depth_bias_fraction_std = c.depth_user_bias_fraction_std = c.depth_noise_fraction_std = 0;
  c.display_noise_px = c.display_bias_px = 0;
  c.motor_noise_fraction = 0;
  c.stop_lateral_arcmin = 0.05;
  c.stop_depth_fraction = 1e-4;
  c.stop_display_px = 0.05;
  c.min_step_m = 1e-5;
  c.min_step_deg = 1e-4;
  c.X_RV_start.translation() = Eigen::Vector3d(0.10, -0.08, 0.05);
  c.X_RV_start.linear() = Eigen::AngleAxisd(0.07, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const EmulatedUser user(c);

  ViewingContext ctx;
  ctx.X_WR.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  ctx.X_WR.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  ctx.X_WH_true = geometry::LookAt({-0.75, -1.4, 1.7}, {0.25, -0.45, 1.25});
  ctx.X_WH_est = ctx.X_WH_true;
  for (const bool with_display : {false, true}) {
    if (with_display) {
      ReflectiveDisplayView d;
      d.X_WC_true = d.X_WC_est = geometry::LookAt({1.45, -1.2, 1.7}, {0.25, -0.45, 1.25});
      ctx.displays.push_back(d);
    }
    const AlignmentResult r = user.Align(ctx, p_RQ, user.StartPose(ctx.X_WR), 42);
    EXPECT_EQ(r.stop_reason, "aligned");
    const PoseError e = EvaluatePose(r.X_WV, ctx.X_WR, p_RQ, ctx.X_WH_true.translation());
    EXPECT_LT(e.translation_error_m, 0.5e-3) << "display " << with_display;
    EXPECT_LT(e.rotation_error_deg, 0.05);
    EXPECT_GT(r.nudges, 3);
    EXPECT_GT(r.duration_s, 0);
    if (with_display) {
      EXPECT_GT(r.display_points_seen, 5);
    }
  }
}

// With tracking perfect and only a depth misjudgement β, the person's error is along the ray and
// about β · ρ (ρ ≈ 1.6 m to the robot's middle).
TEST(EmulatedUser, DepthMisjudgementMovesAlongTheRay) {
  const sim::RobotModel robot = Robot();
  const std::vector<Eigen::Vector3d> p_RQ =
      RobotModelPoints(robot, sim::DegToRad((Eigen::VectorXd(7) << 0, 20, 0, -70, 0, 60, 0).finished()));
  UserConfig c;
  c.lateral_noise_arcmin = c.lateral_bias_arcmin = 0;
  c.depth_bias_fraction_std = c.depth_noise_fraction_std = 0;
  c.user_scale_log_sigma = 0;
  c.depth_user_bias_fraction_std = 0.02;
  c.motor_noise_fraction = 0;
  c.min_step_m = 1e-5;
  c.min_step_deg = 1e-4;
  c.stop_depth_fraction = 1e-4;
  c.stop_lateral_arcmin = 0.05;
  ViewingContext ctx;
  ctx.X_WR.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  ctx.X_WH_true = ctx.X_WH_est = geometry::LookAt({-0.75, -1.4, 1.7}, {0.25, -0.45, 1.25});
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    c.seed = seed;
    const EmulatedUser user(c);
    const AlignmentResult r = user.Align(ctx, p_RQ, user.StartPose(ctx.X_WR), seed);
    const PoseError e = EvaluatePose(r.X_WV, ctx.X_WR, p_RQ, ctx.X_WH_true.translation());
    const double rho = (ctx.X_WR * (Eigen::Vector3d::Zero()) - ctx.X_WH_true.translation()).norm();
    EXPECT_LT(e.lateral_m, 0.15 * e.along_ray_m + 0.5e-3) << "seed " << seed;
    // β · ρ with ρ between the nearest and the farthest model point (1.2 .. 2.2 m).
    const double beta = std::abs(user.depth_user_bias_fraction());
    EXPECT_GT(e.along_ray_m, beta * 1.0 - 1e-3) << rho;
    EXPECT_LT(e.along_ray_m, beta * 2.3 + 1e-3);
  }
}

TEST(EmulatedUser, SeedIsAPersonAndTrialsAreReproducible) {
  UserConfig c;
  c.seed = 1;
  const EmulatedUser a(c);
  c.seed = 2;
  const EmulatedUser b(c);
  EXPECT_NE(a.depth_scale(), b.depth_scale());
  EXPECT_NE(a.depth_user_bias_fraction(), b.depth_user_bias_fraction());
  const std::vector<Eigen::Vector3d> p_RQ = RobotModelPoints(Robot(), Eigen::VectorXd::Zero(7));
  ViewingContext ctx;
  ctx.X_WH_true = ctx.X_WH_est = geometry::LookAt({1.5, -1.2, 1.7}, {0, 0, 1.0});
  const AlignmentResult r1 = a.Align(ctx, p_RQ, a.StartPose(ctx.X_WR), 9);
  const AlignmentResult r2 = a.Align(ctx, p_RQ, a.StartPose(ctx.X_WR), 9);
  EXPECT_TRUE(r1.X_WV.isApprox(r2.X_WV, 0));
  EXPECT_EQ(r1.nudges, r2.nudges);
}

void ExpectSame(const UserConfig& a, const UserConfig& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.lateral_noise_arcmin, b.lateral_noise_arcmin);
  EXPECT_EQ(a.lateral_bias_arcmin, b.lateral_bias_arcmin);
  EXPECT_EQ(a.depth_bias_fraction_std, b.depth_bias_fraction_std);
  EXPECT_EQ(a.depth_user_bias_fraction_std, b.depth_user_bias_fraction_std);
  EXPECT_EQ(a.depth_noise_fraction_std, b.depth_noise_fraction_std);
  EXPECT_EQ(a.user_scale_log_sigma, b.user_scale_log_sigma);
  EXPECT_EQ(a.size_blind, b.size_blind);
  EXPECT_EQ(a.display_noise_px, b.display_noise_px);
  EXPECT_EQ(a.display_bias_px, b.display_bias_px);
  EXPECT_EQ(a.assumed_lateral_arcmin, b.assumed_lateral_arcmin);
  EXPECT_EQ(a.assumed_depth_fraction, b.assumed_depth_fraction);
  EXPECT_EQ(a.assumed_display_px, b.assumed_display_px);
  EXPECT_EQ(a.gain, b.gain);
  EXPECT_EQ(a.motor_noise_fraction, b.motor_noise_fraction);
  EXPECT_EQ(a.max_nudges, b.max_nudges);
  EXPECT_EQ(a.stop_lateral_arcmin, b.stop_lateral_arcmin);
  EXPECT_EQ(a.stop_depth_fraction, b.stop_depth_fraction);
  EXPECT_EQ(a.stop_display_px, b.stop_display_px);
  EXPECT_EQ(a.min_step_m, b.min_step_m);
  EXPECT_EQ(a.min_step_deg, b.min_step_deg);
  EXPECT_EQ(a.look_time_s, b.look_time_s);
  EXPECT_EQ(a.display_look_time_s, b.display_look_time_s);
  EXPECT_EQ(a.nudge_time_s, b.nudge_time_s);
  EXPECT_TRUE(a.X_RV_start.isApprox(b.X_RV_start, 0)) << a.X_RV_start.matrix() << "\n"
                                                      << b.X_RV_start.matrix();
}

// The defaults live in three places that must agree: user_model.h's @code{.yaml} block, UserConfig's
// member initializers and config/user.yaml. Fails when one is edited without the others.
// The person sees a jump beyond their own stopping thresholds (3 arcmin across the line of sight,
// 1 % of the distance along it): at 2 m, 1 mm across is 1.7 arcmin (unseen), 5 mm is 8.6 (seen);
// 15 mm along it is 0.75 % (unseen), 30 mm is 1.5 % (seen).
TEST(EmulatedUser, SeesAJumpBeyondItsThresholds) {
  const EmulatedUser user{UserConfig{}};
  const std::vector<Eigen::Vector3d> p_RQ = {{0, 0, 0}};  // the centroid itself
  const Eigen::Vector3d p_W_eye(-2, 0, 0);                // looking along +x from 2 m
  auto shifted = [](const Eigen::Vector3d& t) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = t;
    return X;
  };
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  EXPECT_FALSE(user.SeesHologramMove(I, I, p_RQ, p_W_eye));
  EXPECT_FALSE(user.SeesHologramMove(I, shifted({0, 0.001, 0}), p_RQ, p_W_eye));
  EXPECT_TRUE(user.SeesHologramMove(I, shifted({0, 0.005, 0}), p_RQ, p_W_eye));
  EXPECT_FALSE(user.SeesHologramMove(I, shifted({0.015, 0, 0}), p_RQ, p_W_eye));
  EXPECT_TRUE(user.SeesHologramMove(I, shifted({0.030, 0, 0}), p_RQ, p_W_eye));
}

TEST(UserConfig, HeaderStructAndShippedFileAgree) {
  const std::string header = orbed::SourceDir() + "/hmd_emulator/user_model.h";
  const std::string file = orbed::SourceDir() + "/" + kDefaultUserConfigRelativePath;
  const YAML::Node doc = YamlFields::LoadDocBlock(header);
  const std::set<std::string> documented = YamlFields::KeyPaths(doc);
  for (const std::string& k : YamlFields::KeyPaths(YamlFields::LoadFile(file))) {
    EXPECT_TRUE(documented.count(k)) << k << ": set in " << file << ", not documented in " << header;
  }
  ExpectSame(ParseUserConfig(doc["user"], header), UserConfig{}, "header vs UserConfig");
  ExpectSame(LoadUserConfigFile(file), UserConfig{}, "config/user.yaml vs UserConfig");
}

TEST(UserConfig, ErrorsNameFileLineAndKey) {
  try {
    ParseUserConfig(YamlFields::LoadString("user:\n  nudging:\n    gain: fast\n", "u.yaml")["user"],
                    "u.yaml");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "u.yaml:3: user.nudging.gain: expected a number in [0.01, 1.5], got 'fast'");
  }
}

}  // namespace
}  // namespace orbed::hmd
