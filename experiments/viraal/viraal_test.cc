// The ViRAAl protocol library: the metrics against hand-computed offsets, the scenario file's
// loading and errors, results.json's shape.
#include <array>
#include <cmath>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/registration_t.hpp>

#include "base/source_paths.h"
#include "base/units.h"
#include "experiments/viraal/exchange.h"
#include "experiments/viraal/metrics.h"
#include "experiments/viraal/protocol.h"
#include "experiments/viraal/results.h"
#include "sim/robot_model.h"

namespace orbed::viraal {
namespace {

// The trocar_or scene's base: (0.25, -0.55, 0.75), yaw 90 deg.
Eigen::Isometry3d SceneBase() {
  Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  X_WR.linear() = Eigen::AngleAxisd(90 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_WR.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  return X_WR;
}

std::string Source(const std::string& relative) { return SourceTreePath(relative); }

TEST(ViraalErrors, RotationAngleIsTheGeodesicAngle) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d dR = Eigen::AngleAxisd(1 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(RotationAngle(R, R * dR), 1 * kDegToRad, 1e-14);
  EXPECT_NEAR(RotationAngle(R, dR * R), 1 * kDegToRad, 1e-14);
  EXPECT_NEAR(RotationAngle(R, R), 0.0, 1e-15);
  // Near π the quaternion form keeps its precision.
  const Eigen::Matrix3d flip = Eigen::AngleAxisd(M_PI - 1e-7, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_NEAR(RotationAngle(Eigen::Matrix3d::Identity(), flip), M_PI - 1e-7, 1e-12);
}

// X_WV = X_WR shifted 10 mm along the base's x and turned 1 deg about its z: X_RV = [Rz(1°), (0.01,0,0)].
TEST(ViraalErrors, TenMillimetresAndOneDegreeInTheBaseFrame) {
  const Eigen::Isometry3d X_WR = SceneBase();
  Eigen::Isometry3d X_RV = Eigen::Isometry3d::Identity();
  X_RV.linear() = Eigen::AngleAxisd(1 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_RV.translation() = Eigen::Vector3d(0.01, 0, 0);
  const Eigen::Isometry3d X_WV = X_WR * X_RV;
  RobotPoints points;
  points.p_RC = Eigen::Vector3d(1, 0, 0);  // 1 m along the base x
  points.p_RF = Eigen::Vector3d(0, 0, 2);  // on the rotation axis: only the shift remains
  points.p_RL = {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1)};
  const AlignmentError e = EvaluateAlignment(X_WR, X_WV, points);
  EXPECT_NEAR(e.rotation_rad, 1 * kDegToRad, 1e-14);
  EXPECT_NEAR(e.base_translation_m, 0.010, 1e-15);
  // |(cos 1° − 1 + 0.01, sin 1°, 0)| = 0.020039051632882905 m (hand/calculator).
  EXPECT_NEAR(e.centroid_translation_m, 0.020039051632882905, 1e-14);
  EXPECT_NEAR(e.flange_translation_m, 0.010, 1e-14);
  ASSERT_EQ(e.p_W_real.size(), 2u);
  ASSERT_EQ(e.p_W_virtual.size(), 2u);
  // Real landmark 0: base x = W +y (yaw 90°) → p_WR + (0, 1, 0).
  EXPECT_NEAR((e.p_W_real[0] - Eigen::Vector3d(0.25, 0.45, 0.75)).norm(), 0.0, 1e-14);
  // Virtual landmark 0 in R: (cos 1° + 0.01, sin 1°, 0) → in W: (−sin 1°, cos 1° + 0.01, 0) + p_WR.
  const Eigen::Vector3d expected(0.25 - std::sin(1 * kDegToRad), -0.55 + std::cos(1 * kDegToRad) + 0.01,
                                 0.75);
  EXPECT_NEAR((e.p_W_virtual[0] - expected).norm(), 0.0, 1e-14);
}

// X_WV = X_WR shifted 10 mm along W x and turned 1 deg about W z at its own origin.
TEST(ViraalErrors, TenMillimetresAndOneDegreeInTheWorldFrame) {
  const Eigen::Isometry3d X_WR = SceneBase();
  Eigen::Isometry3d X_WV = X_WR;
  X_WV.linear() =
      Eigen::AngleAxisd(1 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * X_WR.linear();
  X_WV.translation() += Eigen::Vector3d(0.01, 0, 0);
  RobotPoints points;
  points.p_RC = Eigen::Vector3d(0, 0, 0.634);  // on the (vertical) base z axis: only the shift
  points.p_RF = Eigen::Vector3d(0.5, 0, 0);    // 0.5 m out along base x = W y
  const AlignmentError e = EvaluateAlignment(X_WR, X_WV, points);
  EXPECT_NEAR(e.rotation_rad, 1 * kDegToRad, 1e-14);
  EXPECT_NEAR(e.base_translation_m, 0.010, 1e-15);
  EXPECT_NEAR(e.centroid_translation_m, 0.010, 1e-14);
  // W offset of the flange: (0.01 − 0.5 sin 1°, 0.5 (cos 1° − 1), 0).
  EXPECT_NEAR(e.flange_translation_m,
              std::hypot(0.01 - 0.5 * std::sin(1 * kDegToRad), 0.5 * (std::cos(1 * kDegToRad) - 1)), 1e-14);
}

TEST(ViraalErrors, MeanOverConfigurationsAveragesPointErrorsAndPoolsLandmarks) {
  const Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_WV = Eigen::Isometry3d::Identity();
  X_WV.linear() = Eigen::AngleAxisd(90 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  RobotPoints a, b;
  a.p_RC = Eigen::Vector3d(1, 0, 0);  // moves to (0, 1, 0): sqrt(2)
  b.p_RC = Eigen::Vector3d(0, 0, 1);  // on the axis: 0
  a.p_RL = {Eigen::Vector3d(1, 0, 0)};
  b.p_RL = {Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(0, 0, 3)};
  const AlignmentError e = EvaluateOverConfigurations(X_WR, X_WV, {a, b});
  EXPECT_NEAR(e.centroid_translation_m, std::sqrt(2.0) / 2, 1e-15);
  EXPECT_EQ(e.p_W_real.size(), 3u);
  EXPECT_THROW(EvaluateOverConfigurations(X_WR, X_WV, {}), std::invalid_argument);
}

// A session mean nobody annotated is measured against the real landmarks the user annotated in the
// session's trials, its virtual landmarks placed by the mean itself: here the mean is 10 mm off in
// x and the annotated real landmarks 2 mm off in y, so every pair differs by (10, -2, 0) mm.
TEST(ViraalErrors, TheMeanIsMeasuredAgainstTheAnnotatedRealLandmarks) {
  orbed::pose_t X_WR{};
  X_WR.quaternion_wxyz[0] = 1;
  orbed::registration_t mean{};
  mean.X_WV_mean = X_WR;
  mean.X_WV_mean.position_m[0] = 0.01;
  RobotPoints a, b;
  a.p_RL = {Eigen::Vector3d(1, 0, 0)};
  b.p_RL = {Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(0, 0, 3)};
  const Eigen::Vector3d off(0, 0.002, 0);
  const std::vector<std::vector<Eigen::Vector3d>> annotated = {{a.p_RL[0] + off},
                                                               {b.p_RL[0] + off, b.p_RL[1] + off}};
  const AlignmentError e = MeanError(X_WR, mean, {a, b}, annotated);
  ASSERT_EQ(e.p_W_real_annotated.size(), 3u);
  EXPECT_FALSE(e.virtual_annotated);
  const orbed::misalignment_request_t request = MisalignmentRequest(e, "s", 0, 1);
  ASSERT_EQ(request.num_pairs, 3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(request.p_W_virtual_m[k][0] - request.p_W_real_m[k][0], 0.01, 1e-15);
    EXPECT_NEAR(request.p_W_virtual_m[k][1] - request.p_W_real_m[k][1], -0.002, 1e-15);
    EXPECT_NEAR(request.p_W_virtual_m[k][2] - request.p_W_real_m[k][2], 0, 1e-15);
  }
  orbed::misalignment_t answer{};
  EXPECT_EQ(Measures(e, answer).landmarks, "gaze_real");
  // The truth's pairs stay: the mean alone is 10 mm off.
  EXPECT_NEAR(Measures(e, answer).truth_misalignment_mm, 10.0, 1e-9);
  // One trial without annotation, or none given: the truth's pairs alone.
  EXPECT_TRUE(MeanError(X_WR, mean, {a, b}, {{a.p_RL[0]}, {}}).p_W_real_annotated.empty());
  EXPECT_EQ(Measures(MeanError(X_WR, mean, {a, b}), answer).landmarks, "truth");
  EXPECT_THROW(MeanError(X_WR, mean, {a, b}, {{a.p_RL[0]}}), std::invalid_argument);
  EXPECT_THROW(MeanError(X_WR, mean, {a, b}, {{a.p_RL[0]}, {b.p_RL[0]}}), std::invalid_argument);
  // The right total, the wrong split between the trials: refused, not shifted.
  EXPECT_THROW(MeanError(X_WR, mean, {a, b}, {{a.p_RL[0], b.p_RL[0]}, {b.p_RL[1]}}), std::invalid_argument);
}

// Eye 2 m before the target along W y, at its height: z = W y, x = z × W z = W x (to the right of
// someone looking along +y with z up), y = z × x = −W z (down).
TEST(ViewerFrame, LevelLineOfSightAlongWorldY) {
  const Eigen::Matrix3d R_WS = ViewerFrame(Eigen::Vector3d(0, -2, 1.5), Eigen::Vector3d(0, 0, 1.5));
  EXPECT_NEAR((R_WS.col(0) - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((R_WS.col(1) - Eigen::Vector3d(0, 0, -1)).norm(), 0, 1e-15);
  EXPECT_NEAR((R_WS.col(2) - Eigen::Vector3d(0, 1, 0)).norm(), 0, 1e-15);
  // Looking straight down: x falls back to W x; still a rotation.
  const Eigen::Matrix3d down = ViewerFrame(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0, 0, 0));
  EXPECT_NEAR((down.col(0) - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR(down.determinant(), 1, 1e-15);
  EXPECT_THROW(ViewerFrame(Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1.0005)), std::invalid_argument);
}

// The eye above and beside the robot (a downward, oblique line of sight). The hologram shifted by
// 10 mm along the line of sight from the eye to the landmarks' centroid T: in S the error is
// (0, 0, 10) mm for every pair, while in W it spreads over all three axes (10·|d| per axis). Shifted
// 10 mm horizontally across the line of sight: (10, 0, 0); along S's y (down, in the vertical plane
// of the line of sight): (0, 10, 0).
TEST(ViewerFrame, AnOffsetAlongTheLineOfSightIsDepthOnly) {
  const Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  RobotPoints points;
  points.p_RL = {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)};
  const Eigen::Vector3d p_WT(1.0 / 3, 1.0 / 3, 1.0 / 3);
  const Eigen::Vector3d p_WE(2, -1, 2);
  const Eigen::Vector3d d = (p_WT - p_WE).normalized();  // (−5, 4, −5)/√66
  const Eigen::Vector3d across = d.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = d.cross(across);
  const orbed::misalignment_t answer{};
  const struct {
    Eigen::Vector3d offset_W;
    Eigen::Vector3d viewer_mm;
  } cases[] = {{0.01 * d, {0, 0, 10}}, {0.01 * across, {10, 0, 0}}, {0.01 * down, {0, 10, 0}}};
  for (const auto& c : cases) {
    Eigen::Isometry3d X_WV = X_WR;
    X_WV.translation() += c.offset_W;
    const AlignmentError e = WithViewer(EvaluateAlignment(X_WR, X_WV, points), p_WE);
    ASSERT_EQ(e.R_WS.size(), 3u);
    ASSERT_TRUE(e.p_WE.has_value());
    const ErrorMeasures m = Measures(e, answer);
    ASSERT_TRUE(m.viewer_axes_mm.has_value());
    EXPECT_NEAR((*m.viewer_axes_mm - c.viewer_mm).norm(), 0, 1e-12) << m.viewer_axes_mm->transpose();
  }
  // The W axes of the depth offset: 10 mm · |d| = 10/√66 · (5, 4, 5) mm.
  const Eigen::Vector3d W_mm =
      1e3 * ViewerAxesError({p_WT}, {p_WT + 0.01 * d}, {Eigen::Matrix3d::Identity()});
  EXPECT_NEAR((W_mm - 10 / std::sqrt(66.0) * Eigen::Vector3d(5, 4, 5)).norm(), 0, 1e-12);
  // No eye, no viewer axes.
  EXPECT_FALSE(Measures(EvaluateAlignment(X_WR, X_WR, points), answer).viewer_axes_mm.has_value());
  EXPECT_THROW(ViewerAxesError({p_WT}, {p_WT}, {}), std::invalid_argument);
}

// A session mean 10 mm off along W x, measured in each trial's frame: trial a looked along +W x (the
// offset is its depth, z), trial b along +W y (the offset is across its line of sight, x). a has one
// landmark pair, b two: (2·10, 0, 1·10) / 3 mm.
TEST(ViewerFrame, TheMeanIsMeasuredInEachTrialsFrame) {
  orbed::pose_t X_WR{};
  X_WR.quaternion_wxyz[0] = 1;
  orbed::registration_t mean{};
  mean.X_WV_mean = X_WR;
  mean.X_WV_mean.position_m[0] = 0.01;
  RobotPoints a, b;
  a.p_RL = {Eigen::Vector3d(1, 0, 1)};
  b.p_RL = {Eigen::Vector3d(0, 1, 1), Eigen::Vector3d(0, 3, 1)};  // centroid (0, 2, 1)
  const std::vector<std::optional<Eigen::Vector3d>> eyes = {Eigen::Vector3d(-1, 0, 1),
                                                            Eigen::Vector3d(0, 0, 1)};
  const AlignmentError e = MeanError(X_WR, mean, {a, b}, {}, eyes);
  ASSERT_EQ(e.R_WS.size(), 3u);
  const ErrorMeasures m = Measures(e, orbed::misalignment_t{});
  ASSERT_TRUE(m.viewer_axes_mm.has_value());
  EXPECT_NEAR((*m.viewer_axes_mm - Eigen::Vector3d(20.0 / 3, 0, 10.0 / 3)).norm(), 0, 1e-12);
  // A trial without an eye: no frames for the mean; the wrong count is refused.
  EXPECT_TRUE(MeanError(X_WR, mean, {a, b}, {}, {eyes[0], std::nullopt}).R_WS.empty());
  EXPECT_THROW(MeanError(X_WR, mean, {a, b}, {}, {eyes[0]}), std::invalid_argument);
}

// The eye is where the first ray at each landmark and side starts (the alignment viewpoint).
TEST(ViewerFrame, TheEyeIsWhereTheFirstRaysStart) {
  orbed::AlignmentTrial trial;
  EXPECT_FALSE(AlignmentViewpoint(trial).has_value());
  std::array<orbed::LandmarkRays, 2> sides;
  sides[0].origin_W_m = {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(5, 5, 5)};
  sides[1].origin_W_m = {Eigen::Vector3d(3, 0, 2), Eigen::Vector3d(7, 7, 7)};
  trial.annotation = {sides};
  const std::optional<Eigen::Vector3d> eye = AlignmentViewpoint(trial);
  ASSERT_TRUE(eye.has_value());
  EXPECT_NEAR((*eye - Eigen::Vector3d(2, 0, 1)).norm(), 0, 1e-15);
}

TEST(ViraalErrors, RobotPointsOfTheIiwaUpright) {
  const auto model = orbed::sim::RobotModel::LoadFile(Source("sim/models/iiwa7.urdf"));
  const RobotPointSet set(model, {"iiwa_link_4", "iiwa_link_6", "iiwa_link_ee"});
  const RobotPoints p = set.At(Eigen::VectorXd::Zero(7));
  // DH d = (0.34, 0, 0.4, 0, 0.4, 0, 0.126): origins of link 0..7 and the flange at z = 0, 0,
  // 0.34, 0.34, 0.74, 0.74, 1.14, 1.14, 1.266 → centroid z = 5.706 / 9 = 0.634.
  EXPECT_NEAR((p.p_RC - Eigen::Vector3d(0, 0, 0.634)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((p.p_RF - Eigen::Vector3d(0, 0, 1.266)).norm(), 0.0, 1e-12);
  ASSERT_EQ(p.p_RL.size(), 3u);
  EXPECT_NEAR(p.p_RL[0].z(), 0.74, 1e-12);
  EXPECT_NEAR(p.p_RL[1].z(), 1.14, 1e-12);
  EXPECT_NEAR(p.p_RL[2].z(), 1.266, 1e-12);
  EXPECT_THROW(RobotPointSet(model, {"iiwa_link_9"}), std::invalid_argument);
}

TEST(ScenarioConfig, TheShippedFileLoads) {
  const ScenarioConfig c = LoadScenarioFile(Source(kDefaultScenarioRelativePath));
  EXPECT_EQ(c.trials, 3);
  ASSERT_EQ(c.modes.size(), 2u);
  EXPECT_EQ(c.modes[0].name, "ar_reflective");
  EXPECT_EQ(c.modes[0].display_mode, +orbed::alignment_trial_t::MODE_AR_REFLECTIVE);
  EXPECT_EQ(c.modes[0].num_mirrors, 1);
  EXPECT_EQ(c.modes[1].name, "ar");
  EXPECT_EQ(c.modes[1].num_mirrors, 0);
  EXPECT_EQ(c.method, +orbed::registration_t::METHOD_KARCHER);
  EXPECT_EQ(c.configurations_deg.size(), 3u);
  EXPECT_EQ(c.landmarks.size(), 3u);
}

void ExpectError(const std::string& yaml, const std::string& pattern) {
  try {
    LoadScenarioString(yaml, "s.yaml");
    ADD_FAILURE() << "no error for:\n" << yaml;
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(pattern))) << e.what();
  }
}

TEST(ScenarioConfig, CommandLineOverrides) {
  ScenarioConfig config = LoadScenarioFile(Source(kDefaultScenarioRelativePath));
  ApplyOverrides(&config, 2, "ar,ar_reflective", {"0,10,0,-20,0,30,0", "5,10,0,-20,0,30,0"});
  EXPECT_EQ(config.trials, 2);
  ASSERT_EQ(config.modes.size(), 2u);
  EXPECT_EQ(config.modes[0].num_mirrors, 0);
  EXPECT_EQ(config.modes[1].num_mirrors, 1);
  ASSERT_EQ(config.configurations_deg.size(), 2u);
  EXPECT_EQ(config.configurations_deg[1][0], 5.0);
  EXPECT_EQ(config.configurations_deg[1][6], 0.0);
  ScenarioConfig untouched = LoadScenarioFile(Source(kDefaultScenarioRelativePath));
  const int trials = untouched.trials;
  ApplyOverrides(&untouched, 0, "", {});
  EXPECT_EQ(untouched.trials, trials);
  EXPECT_THROW(ApplyOverrides(&untouched, 0, "ar,mirror", {}), std::invalid_argument);
  EXPECT_THROW(ApplyOverrides(&untouched, 0, "", {"1,x,3"}), std::invalid_argument);
  ApplyOverrides(&untouched, 0, "", {"1,2,3"});  // parses; the size is checked with the rest:
  EXPECT_THROW(ValidateScenarioConfig(untouched, 7), std::invalid_argument);
}

TEST(ScenarioConfig, ErrorsNameTheLineAndTheFix) {
  const std::string good = "configurations_deg:\n  - [0, 30, 0, -60, 0, 45, 0]\nlandmarks: [iiwa_link_ee]\n";
  EXPECT_NO_THROW(LoadScenarioString(good, "s.yaml"));
  ExpectError("trails: 3\n" + good, "s.yaml:1: trails: unknown key");
  ExpectError(good + "modes: [ar, vr]\n",
              "s.yaml:4: modes\\[1\\]: unknown mode 'vr', expected ar_reflective or ar");
  ExpectError(good + "trials: 0\n", "s.yaml:4: trials: expected an integer in \\[1, 1000\\], got '0'");
  ExpectError(good + "method: mean\n", "s.yaml:4: method: expected chordal, karcher or robust");
  ExpectError("configurations_deg:\n  - [0, 30, 0, x, 0, 45, 0]\nlandmarks: [a]\n",
              "s.yaml:2: configurations_deg\\[0\\]\\[3\\]: expected a number");
  ExpectError(
      "configurations_deg:\n  - [0, 30, 0, -60, 0, 45, 0]\n  - [0, 30, 0, -60, 0, 45, 0.5]\nlandmarks: [a]\n",
      "configurations 0 and 1 are the same");
  ExpectError("landmarks: [a]\n", "s.yaml:1: configurations_deg: missing");
  ExpectError(good + "reflective_mirrors: 2\ncapture_waypoints: [foot_end]\n",
              "capture_waypoints: 1 waypoint\\(s\\) for the 2 display\\(s\\) of mode ar_reflective");
  ExpectError(good + "capture_waypoints: foot_end\n", "s.yaml:4: capture_waypoints: expected a list");
  ExpectError(good + "capture_waypoints: [\"foot end\"]\n",
              "capture_waypoints: 'foot end' is not a waypoint name");
  ExpectError(good + "capture_waypoints: [" + std::string(65, 'w') + "]\n",
              "is not a waypoint name \\(1..64");
  EXPECT_EQ(LoadScenarioString(good + "capture_waypoints: [head_end]\n", "s.yaml").capture_waypoints,
            (std::vector<std::string>{"head_end"}));
  EXPECT_THROW(ParseJointList("1,2,x", "--q-deg"), std::invalid_argument);
  EXPECT_EQ(ParseJointList("1, 2.5,-3", "--q-deg"), (std::vector<double>{1, 2.5, -3}));
}

TEST(ViraalResults, MeanStdWithTheSampleDenominator) {
  const MeanStd s = ComputeMeanStd({1, 2, 3});
  EXPECT_DOUBLE_EQ(s.mean, 2.0);
  EXPECT_DOUBLE_EQ(s.std, 1.0);
  EXPECT_DOUBLE_EQ(ComputeMeanStd({5}).std, 0.0);
}

int Count(const std::string& text, const std::string& pattern) {
  const std::regex re(pattern);
  return static_cast<int>(
      std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
}

// Two trials m ∓ s/√2 per axis have mean m and sample standard deviation s, so the row of the
// paper's own per-axis figures must give the paper's norms (Table 1, rounded as printed there).
TEST(ViraalResults, Table1RowGivesThePapersNormsFromItsPerAxisFigures) {
  struct PaperRow {
    Eigen::Vector3d mean, std;
    double mean_norm, std_norm;
  };
  const PaperRow rows[] = {{{17.4, 11.9, 21.6}, {16.1, 6.24, 16.5}, 30.2, 23.9},   // AR only
                           {{9.00, 10.3, 9.18}, {5.64, 7.45, 5.77}, 16.5, 11.0}};  // with the display
  for (const PaperRow& p : rows) {
    const Eigen::Vector3d half_spread = p.std / std::sqrt(2.0);
    const Table1Row row = ComputeTable1Row({p.mean - half_spread, p.mean + half_spread});
    EXPECT_EQ(row.num_trials, 2);
    EXPECT_NEAR((row.axes_mean_mm - p.mean).norm(), 0.0, 1e-12);
    EXPECT_NEAR((row.axes_std_mm - p.std).norm(), 0.0, 1e-12);
    EXPECT_NEAR(row.mean_mm, p.mean_norm, 0.05);
    EXPECT_NEAR(row.std_mm, p.std_norm, 0.05);
  }
}

// By hand: trials (3, 0, 4), (1, 2, 2), (2, 1, 0): means (2, 1, 2) → 3; sample stds (1, 1, 2) → √6.
// The mean of the trials' norms is (5 + 3 + √5)/3 ≈ 3.41, larger than 3 (triangle inequality).
TEST(ViraalResults, Table1RowIsTheNormOfPerAxisMeansNotTheMeanOfNorms) {
  SessionResult s;
  for (const Eigen::Vector3d& axes :
       {Eigen::Vector3d(3, 0, 4), Eigen::Vector3d(1, 2, 2), Eigen::Vector3d(2, 1, 0)}) {
    TrialResult t;
    t.errors.misalignment_axes_mm = axes;
    t.errors.misalignment_mm = axes.norm();
    s.trials.push_back(t);
  }
  const Table1Row row = SessionTable1Row(s);
  EXPECT_EQ(row.num_trials, 3);
  EXPECT_NEAR((row.axes_mean_mm - Eigen::Vector3d(2, 1, 2)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((row.axes_std_mm - Eigen::Vector3d(1, 1, 2)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(row.mean_mm, 3.0, 1e-12);
  EXPECT_NEAR(row.std_mm, std::sqrt(6.0), 1e-12);
  EXPECT_EQ(ComputeTable1Row({}).num_trials, 0);
  EXPECT_EQ(ComputeTable1Row({{1, 2, 2}}).std_mm, 0.0);  // one trial: no spread
}

TEST(ViraalResults, JsonHasTheDocumentedShape) {
  RunResults r;
  r.run_id = "t";
  r.ok = true;
  for (const char* mode : {"ar_reflective", "ar"}) {
    SessionResult s;
    s.mode = mode;
    for (int i = 0; i < 3; ++i) {
      TrialResult t;
      t.index = i;
      t.q_deg = {0, 30, 0, -60, 0, 45, 0};
      t.errors.translation_error_mm = 10 + i;
      s.trials.push_back(t);
    }
    s.mean = MeanResult{};
    r.sessions.push_back(s);
  }
  const std::string json = ResultsJson(r);
  EXPECT_EQ(Count(json, "\"mode\": \"ar_reflective\""), 1);
  EXPECT_EQ(Count(json, "\"mode\": \"ar\""), 1);
  EXPECT_EQ(Count(json, "\"index\": [0-2]"), 6);
  EXPECT_EQ(Count(json, "\"q_deg\": \\["), 6);
  EXPECT_EQ(Count(json, "\"mean\": \\{"), 2);
  // Per trial and per mean, the three required measures.
  EXPECT_EQ(Count(json, "\"translation_error_mm\": "), 6 + 2 + 2);  // + trial_statistics
  EXPECT_EQ(Count(json, "\"rotation_error_deg\": "), 6 + 2 + 2);
  EXPECT_EQ(Count(json, "\"misalignment_mm\": "), 6 + 2 + 2 + 3);  // + paper_reference
  EXPECT_NE(json.find("\"status\": \"ok\""), std::string::npos);
  // translation_error_mm 10, 11, 12: mean 11, std 1.
  EXPECT_NE(json.find("\"translation_error_mm\": {\n          \"mean\": 11.0,\n          \"std\": 1.0"),
            std::string::npos)
      << json;
  EXPECT_EQ(Count(json, "\"table1\": \\{"), 2);
  EXPECT_EQ(Count(json, "\"num_trials\": 3"), 2);
  const std::string table = ResultsTable(r);
  EXPECT_NE(table.find("paper: 16.5 +/- 11.0 mm"), std::string::npos) << table;
  EXPECT_EQ(Count(table, "Table 1 \\(3 trials\\): 0.0 \\+/- 0.0 mm"), 2) << table;
}

}  // namespace
}  // namespace orbed::viraal
