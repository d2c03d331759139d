// The emulated ViRAAl user. Oracles: the truth (a perfect perceiver with perfect tracking ends at
// X_WR), the geometry of the viewing ray, and the statistical claims of the paper's Table 1 tested
// with the rank test of stats.h (whose own oracles are hand computations).
#include "hmd_emulator/user_model.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <string>
#include "base/source_paths.h"

#include <gtest/gtest.h>

#include "base/stats.h"
#include "base/units.h"
#include "base/yaml_fields.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

sim::RobotModel Robot() {
  return sim::RobotModel::LoadFile(orbed::SourceDir() + "/" + sim::RobotModel::kDefaultUrdfRelativePath);
}

// The model points of the arm bent at (0, 20, 0, -70, 0, 60, 0) deg.
std::vector<Eigen::Vector3d> BentArmPoints() {
  return RobotModelPoints(Robot(), sim::DegToRad((Eigen::VectorXd(7) << 0, 20, 0, -70, 0, 60, 0).finished()));
}

// A person whose eyes and hand make no error (what each test then adds back is its subject).
UserConfig PerfectPerson() {
  UserConfig c;
  c.lateral_noise_arcmin = c.lateral_bias_arcmin = 0;
  c.depth_bias_fraction_std = c.depth_user_bias_fraction_std = c.depth_noise_fraction_std = 0;
  c.motor_noise_fraction = c.motor_noise_translation_mm = c.motor_noise_rotation_deg = 0;
  return c;
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
  const std::vector<Eigen::Vector3d> p_RQ = BentArmPoints();
  UserConfig c = PerfectPerson();
  c.stop_lateral_arcmin = 0.05;
  c.stop_depth_fraction = 1e-4;
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

// The hand's noise that does not shrink with the nudge: a perfect perceiver whose hand turns each
// nudge by 1 deg per axis at random ends with rotation errors of that order, mostly about axes
// across the line of sight (a turn there moves the model in depth, which the eye judges to 1 %
// of the distance: 15 mm at 1.5 m, 4 deg over 0.2 m), while without the noise they are below
// 0.05 deg (PerfectPerceiverFindsTheTruth).
TEST(EmulatedUser, WhatTheHandTurnsAcrossTheLineOfSightStays) {
  const std::vector<Eigen::Vector3d> p_RQ = BentArmPoints();
  UserConfig c = PerfectPerson();
  c.motor_noise_rotation_deg = 1.0;
  c.patience_nudges = 0;  // the person nudges on while they see anything: only depth hides the turn
  const EmulatedUser user(c);
  ViewingContext ctx;
  ctx.X_WR.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  ctx.X_WH_true = ctx.X_WH_est = geometry::LookAt({-0.75, -1.4, 1.7}, {0.25, -0.45, 1.25});
  const Eigen::Vector3d line_of_sight = ctx.X_WH_true.linear().col(2);
  std::vector<double> angles_deg;
  int mostly_across = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const AlignmentResult r = user.Align(ctx, p_RQ, user.StartPose(ctx.X_WR), seed);
    const Eigen::AngleAxisd error(ctx.X_WR.linear().transpose() * r.X_WV.linear());
    const Eigen::Vector3d w_W = ctx.X_WR.linear() * (error.angle() * error.axis());
    angles_deg.push_back(error.angle() / kDegToRad);
    mostly_across += (w_W - w_W.dot(line_of_sight) * line_of_sight).norm() > std::abs(w_W.dot(line_of_sight));
  }
  std::sort(angles_deg.begin(), angles_deg.end());
  EXPECT_GT(angles_deg[10], 0.3);  // the median
  EXPECT_LT(angles_deg[10], 3.0);
  EXPECT_GE(mostly_across, 15);
}

// A person whose thresholds cannot be met (0) and whose hand keeps missing gives up after
// patience_nudges nudges in a row without a better look; without patience they nudge to max_nudges.
TEST(EmulatedUser, APersonWhoseNudgesStopHelpingGivesUp) {
  const std::vector<Eigen::Vector3d> p_RQ = BentArmPoints();
  UserConfig c = PerfectPerson();
  c.motor_noise_translation_mm = 2.0;
  c.motor_noise_rotation_deg = 1.0;
  c.stop_lateral_arcmin = c.stop_depth_fraction = 0;
  c.min_step_m = c.min_step_deg = 0;
  c.max_nudges = 60;
  ViewingContext ctx;
  ctx.X_WR.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  ctx.X_WH_true = ctx.X_WH_est = geometry::LookAt({-0.75, -1.4, 1.7}, {0.25, -0.45, 1.25});
  c.patience_nudges = 2;
  const AlignmentResult patient = EmulatedUser(c).Align(ctx, p_RQ, EmulatedUser(c).StartPose(ctx.X_WR), 5);
  EXPECT_EQ(patient.stop_reason, "gave_up");
  EXPECT_LT(patient.nudges, c.max_nudges);
  EXPECT_GE(patient.nudges, 2);
  c.patience_nudges = 0;
  const AlignmentResult stubborn = EmulatedUser(c).Align(ctx, p_RQ, EmulatedUser(c).StartPose(ctx.X_WR), 5);
  EXPECT_EQ(stubborn.stop_reason, "max_nudges");
  EXPECT_EQ(stubborn.nudges, c.max_nudges);
}

// With tracking perfect and only a depth misjudgement β, the person's error is along the ray and
// about β · ρ (ρ ≈ 1.6 m to the robot's middle).
TEST(EmulatedUser, DepthMisjudgementMovesAlongTheRay) {
  const std::vector<Eigen::Vector3d> p_RQ = BentArmPoints();
  UserConfig c = PerfectPerson();
  c.user_scale_log_sigma = 0;
  c.depth_user_bias_fraction_std = 0.02;
  // The whole robot in view: the mechanism, not what a narrow field of view leaves of it.
  c.fov_h_deg = c.fov_v_deg = 170;
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
  EXPECT_EQ(a.fov_h_deg, b.fov_h_deg);
  EXPECT_EQ(a.fov_v_deg, b.fov_v_deg);
  EXPECT_EQ(a.occlusion, b.occlusion);
  EXPECT_EQ(a.assumed_lateral_arcmin, b.assumed_lateral_arcmin);
  EXPECT_EQ(a.assumed_depth_fraction, b.assumed_depth_fraction);
  EXPECT_EQ(a.gain, b.gain);
  EXPECT_EQ(a.motor_noise_fraction, b.motor_noise_fraction);
  EXPECT_EQ(a.motor_noise_translation_mm, b.motor_noise_translation_mm);
  EXPECT_EQ(a.motor_noise_rotation_deg, b.motor_noise_rotation_deg);
  EXPECT_EQ(a.max_nudges, b.max_nudges);
  EXPECT_EQ(a.stop_lateral_arcmin, b.stop_lateral_arcmin);
  EXPECT_EQ(a.stop_depth_fraction, b.stop_depth_fraction);
  EXPECT_EQ(a.min_step_m, b.min_step_m);
  EXPECT_EQ(a.min_step_deg, b.min_step_deg);
  EXPECT_EQ(a.patience_nudges, b.patience_nudges);
  EXPECT_EQ(a.look_time_s, b.look_time_s);
  EXPECT_EQ(a.display_look_time_s, b.display_look_time_s);
  EXPECT_EQ(a.nudge_time_s, b.nudge_time_s);
  EXPECT_TRUE(a.X_RV_start.isApprox(b.X_RV_start, 0)) << a.X_RV_start.matrix() << "\n"
                                                      << b.X_RV_start.matrix();
}

// A ball of radius 0.1 m at the origin between an eye at x = -2 and points beyond it: a point
// straight behind is hidden; one 0.11 m off the sight line's closest approach is seen; a point
// inside the ball is seen (on its own surface); a point in front is seen.
TEST(SeenPast, ASolidHidesWhatIsBehindItOnly) {
  const std::vector<SightSolid> ball = {{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.1}};
  const Eigen::Vector3d eye(-2, 0, 0);
  EXPECT_FALSE(SeenPast(ball, eye, {1, 0, 0}));
  // The line from (-2, 0, 0) to (2, 0.22, 0) passes the origin at 0.22 / 2 = 0.11 m (to 0.15 %).
  EXPECT_TRUE(SeenPast(ball, eye, {2, 0.22, 0}));
  EXPECT_FALSE(SeenPast(ball, eye, {2, 0.18, 0}));  // 0.09 m: inside the ball's radius
  EXPECT_TRUE(SeenPast(ball, eye, {0.05, 0, 0}));
  EXPECT_TRUE(SeenPast(ball, eye, {-0.5, 0, 0}));
  // A capsule along z from -0.5 to 0.5: hides a point behind any part of it, not one above it.
  const std::vector<SightSolid> capsule = {{{0, 0, -0.5}, {0, 0, 0.5}, 0.05}};
  EXPECT_FALSE(SeenPast(capsule, eye, {2, 0, 0.4}));
  EXPECT_TRUE(SeenPast(capsule, eye, {2, 0, 1.3}));  // passes z = 0.65 at x = 0
  EXPECT_TRUE(SeenPast({}, eye, {1, 0, 0}));
}

// One solid per collision primitive; every model point lies inside (or on) some solid; on the
// upright arm seen from the side at the base's height, the base column hides nothing of the arm
// above it, and seen from straight above the flange hides the links below.
TEST(RobotSightSolids, CoverTheModelPoints) {
  const sim::RobotModel robot = Robot();
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
  const std::vector<SightSolid> solids = RobotSightSolids(robot, q);
  std::size_t primitives = 0;
  for (const auto& link : robot.links()) primitives += link.collision.size();
  EXPECT_EQ(solids.size(), primitives);
  const std::vector<Eigen::Vector3d> p_RQ = RobotModelPoints(robot, q);
  for (const Eigen::Vector3d& p : p_RQ) {
    double nearest = INFINITY;
    for (const SightSolid& s : solids) {
      const Eigen::Vector3d ab = s.p_RB - s.p_RA;
      const double t =
          ab.squaredNorm() > 0 ? std::clamp((p - s.p_RA).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
      nearest = std::min(nearest, (p - (s.p_RA + t * ab)).norm() - s.radius_m);
    }
    EXPECT_LE(nearest, 1e-9) << p.transpose();
  }
  int seen_from_side = 0, seen_from_above = 0;
  for (const Eigen::Vector3d& p : p_RQ) {
    seen_from_side += SeenPast(solids, {3, 0, 0.6}, p);
    seen_from_above += SeenPast(solids, {0, 0, 4}, p);
  }
  EXPECT_GE(seen_from_side, static_cast<int>(p_RQ.size()) - 2);  // at most the far side's points
  EXPECT_LE(seen_from_above, 3);                                 // the tool's end and the flange
}

// The panel: D = 2 m puts it 1 m in front of the camera at scale s = 1 m, i.e. 1/fx m per px; seen
// from 1.5 m that is 1.5 fx px per radian, and a 30 deg field of view takes in tan(15 deg) of that
// either side of the centre.
TEST(SeePanel, ResolutionAndFieldOfViewFollowFromSizeAndDistance) {
  ReflectiveDisplayView d;
  d.D_m = 2.0;
  d.X_WC_est = geometry::LookAt({0, 0, 0}, {1, 0, 0});  // z_C along +x: the panel centre at (1, 0, 0)
  const Eigen::Vector3d eye(1, -1.5, 0);
  const PanelView v = SeePanel(d, Eigen::Isometry3d::Identity(), eye, 30, 17.5);
  EXPECT_NEAR(v.distance_m, 1.5, 1e-12);
  EXPECT_NEAR(v.px_per_rad.x(), 1.5 * d.intrinsics.fx_px, 1e-9);
  EXPECT_NEAR(v.px_per_rad.y(), 1.5 * d.intrinsics.fy_px, 1e-9);
  EXPECT_NEAR(v.half_view_px.x(), std::tan(15 * M_PI / 180) * 1.5 * d.intrinsics.fx_px, 1e-9);
  EXPECT_NEAR(v.half_view_px.y(), std::tan(8.75 * M_PI / 180) * 1.5 * d.intrinsics.fy_px, 1e-9);
  // Twice as far, or a panel half as large (D halved): twice as many camera px per radian.
  const PanelView far = SeePanel(d, Eigen::Isometry3d::Identity(), Eigen::Vector3d(1, -3, 0), 30, 17.5);
  EXPECT_NEAR(far.px_per_rad.x(), 2 * v.px_per_rad.x(), 1e-9);
  d.D_m = 1.0;  // panel 0.5 m from the camera, so 1.5 m → sqrt(0.5² + 1.5²) from this eye
  const PanelView small = SeePanel(d, Eigen::Isometry3d::Identity(), eye, 30, 17.5);
  EXPECT_NEAR(small.px_per_rad.x(), std::hypot(0.5, 1.5) * d.intrinsics.fx_px / 0.5, 1e-9);
  d.D_m = NAN;
  EXPECT_THROW(SeePanel(d, Eigen::Isometry3d::Identity(), eye, 30, 17.5), std::invalid_argument);
}

// The field of view: a person whose head is turned away from the robot sees no hologram and cannot
// align; one whose head is on the robot's middle compares only the points inside 30 × 17.5 deg,
// fewer than with an unlimited view; the robot's own solids hide some more.
TEST(EmulatedUser, SeesOnlyWhatIsInViewAndUnhidden) {
  const sim::RobotModel robot = Robot();
  const Eigen::VectorXd q = sim::DegToRad((Eigen::VectorXd(7) << 0, 20, 0, -70, 0, 60, 0).finished());
  const std::vector<Eigen::Vector3d> p_RQ = RobotModelPoints(robot, q);
  UserConfig c;
  ViewingContext ctx;
  ctx.X_WR.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  ctx.X_WH_true = ctx.X_WH_est = geometry::LookAt({-0.75, -1.4, 1.7}, {-3, -4, 1.7});  // away
  const AlignmentResult away = EmulatedUser(c).Align(ctx, p_RQ, EmulatedUser(c).StartPose(ctx.X_WR), 3);
  EXPECT_EQ(away.stop_reason, "nothing_in_view");
  EXPECT_EQ(away.nudges, 0);
  EXPECT_EQ(away.direct_points_seen, 0);

  ctx.X_WH_true = ctx.X_WH_est = geometry::LookAt({-0.75, -1.4, 1.7}, {0.25, -0.45, 1.25});
  auto seen_at_start = [&](const UserConfig& config) {
    UserConfig one_look = config;
    one_look.max_nudges = 1;
    const EmulatedUser user(one_look);
    return user.Align(ctx, p_RQ, ctx.X_WR, 3).direct_points_seen;  // the hologram on the robot
  };
  UserConfig wide = c;
  wide.fov_h_deg = wide.fov_v_deg = 170;
  const int all = seen_at_start(wide);
  const int in_view = seen_at_start(c);
  EXPECT_EQ(all, static_cast<int>(p_RQ.size()));
  EXPECT_GT(in_view, 3);
  EXPECT_LT(in_view, all);
  // Counted by hand: the points inside the view cone about the head's z axis.
  const Eigen::Isometry3d X_HW = ctx.X_WH_true.inverse();
  int expected = 0;
  for (const auto& p : p_RQ) {
    const Eigen::Vector3d p_H = X_HW * (ctx.X_WR * p);
    expected += p_H.z() > 0 && std::abs(p_H.x() / p_H.z()) <= std::tan(15 * M_PI / 180) &&
                std::abs(p_H.y() / p_H.z()) <= std::tan(8.75 * M_PI / 180);
  }
  EXPECT_EQ(in_view, expected);
  ctx.solids_R = RobotSightSolids(robot, q);
  const int unhidden = seen_at_start(wide);
  int expected_unhidden = 0;
  const Eigen::Vector3d p_R_eye = ctx.X_WR.inverse() * ctx.X_WH_true.translation();
  for (const auto& p : p_RQ) expected_unhidden += SeenPast(ctx.solids_R, p_R_eye, p);
  EXPECT_EQ(unhidden, expected_unhidden);
  EXPECT_LT(unhidden, all);  // the arm hides some of itself from the alignment point
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
