// The emulated set-up assistant's core (assistant.h) on the shipped iiwa 7 model. Oracles: the
// model's geometry (which skeleton points lie on which axis), the iiwa's half-turn identity
// (q_j + 180 deg, -q_j+1 gives the same elbow line), closed-form angles and times.
#include "procs/assistant/assistant.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <orbed/guidance_t.hpp>

#include "base/source_paths.h"
#include "base/units.h"
#include "procs/assistant/assistant_test_people.h"

namespace orbed::assistant {
namespace {

using test::Model;
using test::Perfect;

constexpr double kInf = std::numeric_limits<double>::infinity();

Viewing Overlay(const Eigen::Isometry3d& X_WR) {
  Viewing v;
  v.mode = orbed::guidance_t::MODE_AR;
  v.X_WR = X_WR;
  v.X_WV_seen = X_WR;  // a perfect registration, no SLAM error
  v.p_WE = X_WR * Eigen::Vector3d(1.0, -0.6, 0.9);
  return v;
}

Eigen::VectorXd Deg(std::initializer_list<double> q) {
  Eigen::VectorXd out(static_cast<int>(q.size()));
  int i = 0;
  for (double x : q) out[i++] = x * kDegToRad;
  return out;
}

TEST(Assistant, ShippedConfigEqualsTheDefaults) {
  const AssistantConfig file = LoadAssistantConfig(SourceTreePath(kDefaultConfigRelativePath));
  const AssistantConfig d;
  EXPECT_EQ(file.seed, d.seed);
  EXPECT_TRUE(file.eye_position_m.isApprox(d.eye_position_m));
  EXPECT_TRUE(file.monitor_camera_m.isApprox(d.monitor_camera_m));
  EXPECT_EQ(file.user_scale_log_sigma, d.user_scale_log_sigma);
  EXPECT_EQ(file.lateral_noise_arcmin, d.lateral_noise_arcmin);
  EXPECT_EQ(file.depth_noise_fraction_std, d.depth_noise_fraction_std);
  EXPECT_EQ(file.mental_rotation_std_deg, d.mental_rotation_std_deg);
  EXPECT_EQ(file.picture_scale_log_sigma, d.picture_scale_log_sigma);
  EXPECT_EQ(file.picture_noise_arcmin, d.picture_noise_arcmin);
  EXPECT_EQ(file.picture_depth_fraction_std, d.picture_depth_fraction_std);
  EXPECT_EQ(file.match_margin, d.match_margin);
  EXPECT_EQ(file.looks_per_joint, d.looks_per_joint);
  EXPECT_EQ(file.correction_window_deg, d.correction_window_deg);
  EXPECT_EQ(file.placement_noise_deg, d.placement_noise_deg);
  EXPECT_EQ(file.flange_marker_offset_m, d.flange_marker_offset_m);
  EXPECT_EQ(file.joint_overhead_s, d.joint_overhead_s);
  EXPECT_EQ(file.look_s, d.look_s);
  EXPECT_EQ(file.mental_rotation_deg_per_s, d.mental_rotation_deg_per_s);
  EXPECT_EQ(file.hand_speed_deg_per_s, d.hand_speed_deg_per_s);
  EXPECT_EQ(file.pace_log_sigma, d.pace_log_sigma);
}

TEST(Assistant, RefusesBadConfigsNamingTheKey) {
  const std::string dir = ::testing::TempDir();
  auto write = [&](const std::string& text) {
    const std::string path = dir + "/assistant_bad.yaml";
    FILE* f = std::fopen(path.c_str(), "w");
    std::fputs(text.c_str(), f);
    std::fclose(f);
    return path;
  };
  try {
    LoadAssistantConfig(write("assistant:\n  headset: {lateral_noise_arcmin: -1}\n"));
    FAIL() << "a negative noise was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("assistant.headset.lateral_noise_arcmin"), std::string::npos)
        << e.what();
  }
  try {
    LoadAssistantConfig(write("assistant:\n  time: {look_seconds: 3}\n"));
    FAIL() << "an unknown key was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("look_seconds"), std::string::npos) << e.what();
  }
}

// The iiwa's twisting links (1, 3, 5, 7 without the flange mark) have their whole skeleton on their
// joint's axis: their own shape says nothing of the twist.
TEST(Assistant, TwistingLinksAreRoundAboutTheirAxis) {
  const sim::RobotModel model = Model();
  AssistantConfig c = Perfect();
  c.flange_marker_offset_m = 0;
  const Assistant a(model, c);
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(Eigen::VectorXd::Zero(7));
  for (int j : {0, 2, 4, 6}) {
    const int body = model.links()[model.joints()[j].link].body;
    const Eigen::Isometry3d X_RJ = X_RL[model.joints()[j].link];
    const Eigen::Vector3d axis = X_RJ.linear() * model.links()[model.joints()[j].link].axis_J;
    int on_body = 0;
    for (const Feature& f : a.features(j)) {
      if (model.links()[f.link].body != body) continue;
      ++on_body;
      const Eigen::Vector3d p = X_RL[f.link] * f.p_L - X_RJ.translation();
      EXPECT_LT((p - p.dot(axis) * axis).norm(), 1e-9)
          << "joint " << j + 1 << " link " << model.links()[f.link].name;
    }
    EXPECT_GT(on_body, 0);
  }
}

// With the arm straight (joint 2 at 0 in the real arm and the target), nothing the person sees
// depends on joint 1: every angle looks right and the joint stays where it is.
TEST(Assistant, AnInvisibleTwistIsLeftWhereItIs) {
  const sim::RobotModel model = Model();
  Assistant a(model, Perfect());
  const Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  const JointLook look =
      a.Look(0, Deg({25, 0, 0, 0, 0, 0, 0}), Deg({-70, 0, 0, -40, 0, 0, 0}), Overlay(X_WR), kInf);
  EXPECT_EQ(look.ranges, 1);
  EXPECT_NEAR(look.q_rad * kRadToDeg, 25.0, 1e-9);
}

// A revolving joint swings a long link: a near-perfect perceiver puts it on the target.
TEST(Assistant, AClearRevolvingJointLandsOnTheTarget) {
  const sim::RobotModel model = Model();
  Assistant a(model, Perfect());
  const Eigen::VectorXd q_target = Deg({0, 45, 0, -60, 0, 30, 0});
  const JointLook look =
      a.Look(1, Deg({0, -10, 0, -60, 0, 30, 0}), q_target, Overlay(Eigen::Isometry3d::Identity()), kInf);
  EXPECT_EQ(look.ranges, 1);
  EXPECT_NEAR(look.q_rad * kRadToDeg, 45.0, 0.5);
}

// Joint 1 seen through link 2: with the real elbow bent the same way as the target's, joint 1 goes
// to the target; bent the other way, the best match is half a turn away (q1 + 180 deg, -q2 is the
// same elbow line), and the person turns the wrong way round.
TEST(Assistant, TheNextJointsBendDecidesWhichWayATwistGoes) {
  const sim::RobotModel model = Model();
  const Viewing view = Overlay(Eigen::Isometry3d::Identity());
  const Eigen::VectorXd q_target = Deg({60, 30, 0, 0, 0, 0, 0});
  {
    Assistant a(model, Perfect());
    const JointLook look = a.Look(0, Deg({0, 30, 0, 0, 0, 0, 0}), q_target, view, kInf);
    EXPECT_NEAR(look.q_rad * kRadToDeg, 60.0, 0.5);
  }
  {
    Assistant a(model, Perfect());
    const JointLook look = a.Look(0, Deg({0, -30, 0, 0, 0, 0, 0}), q_target, view, kInf);
    EXPECT_NEAR(look.q_rad * kRadToDeg, 60.0 - 180.0, 0.5);
  }
}

// A correcting look searches only its window.
TEST(Assistant, ACorrectingLookStaysInItsWindow) {
  const sim::RobotModel model = Model();
  Assistant a(model, Perfect());
  const JointLook look = a.Look(1, Deg({0, -10, 0, -60, 0, 30, 0}), Deg({0, 45, 0, -60, 0, 30, 0}),
                                Overlay(Eigen::Isometry3d::Identity()), 20 * kDegToRad);
  EXPECT_NEAR(look.q_rad * kRadToDeg, 10.0, 1e-6);  // the window's edge nearest the target
}

// The hologram where the registration puts it. People judge which way a link points from its joint:
// a hologram shifted 3 cm moves no joint's match (to within the grid and the near-perfect eye); one
// turned 3 deg about the vertical turns joint 1's match by 3 deg.
TEST(Assistant, ARegistrationTiltMovesTheMatchAShiftDoesNot) {
  const sim::RobotModel model = Model();
  const Eigen::VectorXd q_target = Deg({20, 45, 0, -30, 0, 30, 0});
  const Eigen::VectorXd q_now = Deg({0, 45, 0, -30, 0, 30, 0});
  {
    Assistant a(model, Perfect());
    Viewing view = Overlay(Eigen::Isometry3d::Identity());
    view.X_WV_seen.translation() = Eigen::Vector3d(0.02, -0.01, 0.03);
    EXPECT_NEAR(a.Look(0, q_now, q_target, view, kInf).q_rad * kRadToDeg, 20.0, 0.3);
  }
  {
    Assistant a(model, Perfect());
    Viewing view = Overlay(Eigen::Isometry3d::Identity());
    view.X_WV_seen.linear() = Eigen::AngleAxisd(3 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    EXPECT_NEAR(a.Look(0, q_now, q_target, view, kInf).q_rad * kRadToDeg, 23.0, 0.3);
  }
}

TEST(Assistant, TimesInClosedForm) {
  const sim::RobotModel model = Model();
  AssistantConfig c = Perfect();
  c.monitor_camera_m = Eigen::Vector3d(0, 2, 1.5);
  Assistant a(model, c);
  EXPECT_NEAR(a.TravelTime_s(90 * kDegToRad), 90.0 / c.hand_speed_deg_per_s, 1e-12);
  Viewing view = Overlay(Eigen::Isometry3d::Identity());
  view.mode = orbed::guidance_t::MODE_FIXED_DISPLAY;
  view.p_WE = Eigen::Vector3d(3, 0, 1.7);
  EXPECT_NEAR(a.MonitorDisparityDeg(view), 90.0, 1e-9);
  const JointLook look = a.Look(1, Deg({0, 0, 0, 0, 0, 0, 0}), Deg({0, 20, 0, 0, 0, 0, 0}), view, kInf);
  EXPECT_NEAR(look.time_s, c.look_s + 90.0 / c.mental_rotation_deg_per_s, 1e-9);
  EXPECT_NEAR(look.q_rad * kRadToDeg, 20.0, 0.5);  // no mental rotation error: the picture is right
}

// FIXED_VIEW's camera (a view the user turned) replaces the config's: a picture taken from the
// person's own side needs no mental rotation, one from the opposite side half a turn.
TEST(Assistant, TheMonitorsCameraFromTheBusSetsTheMentalRotation) {
  const sim::RobotModel model = Model();
  AssistantConfig c = Perfect();
  c.monitor_camera_m = Eigen::Vector3d(0, 2, 1.5);
  Assistant a(model, c);
  Viewing view = Overlay(Eigen::Isometry3d::Identity());
  view.mode = orbed::guidance_t::MODE_FIXED_DISPLAY;
  view.p_WE = Eigen::Vector3d(3, 0, 1.7);
  view.p_WD = Eigen::Vector3d(2, 0, 2.5);  // beside the eye
  EXPECT_NEAR(a.MonitorDisparityDeg(view), 0.0, 1e-9);
  EXPECT_NEAR(a.Look(1, Deg({0, 0, 0, 0, 0, 0, 0}), Deg({0, 20, 0, 0, 0, 0, 0}), view, kInf).time_s, c.look_s,
              1e-9);
  view.p_WD = Eigen::Vector3d(-2, 0, 2.5);  // facing the person across the robot
  EXPECT_NEAR(a.MonitorDisparityDeg(view), 180.0, 1e-9);
}

// The pace: every time of a person is p times the model's (closed form at p from the person), p is
// log-normal with mean 1 and log-spread sigma over many persons, and drawing it changes none of the
// person's other draws (the same joint the person puts at the same place with and without it).
TEST(Assistant, APersonsPaceScalesEveryTimeAndNothingElse) {
  const sim::RobotModel model = Model();
  AssistantConfig c = Perfect();
  c.placement_noise_deg = 1.0;  // a draw the pace must not change
  c.pace_log_sigma = 0.59;
  c.seed = 11;
  Assistant paced(model, c);
  const double p = paced.pace();
  EXPECT_NE(p, 1.0);
  EXPECT_NEAR(paced.TravelTime_s(90 * kDegToRad), p * 90.0 / c.hand_speed_deg_per_s, 1e-12);
  EXPECT_NEAR(paced.JointOverhead_s(), p * c.joint_overhead_s, 1e-12);
  AssistantConfig unpaced_config = c;
  unpaced_config.pace_log_sigma = 0;
  Assistant unpaced(model, unpaced_config);
  EXPECT_EQ(unpaced.pace(), 1.0);
  const Viewing view = Overlay(Eigen::Isometry3d::Identity());
  const JointLook a = paced.Look(1, Deg({0, 0, 0, 0, 0, 0, 0}), Deg({0, 20, 0, 0, 0, 0, 0}), view, kInf);
  const JointLook b = unpaced.Look(1, Deg({0, 0, 0, 0, 0, 0, 0}), Deg({0, 20, 0, 0, 0, 0, 0}), view, kInf);
  EXPECT_EQ(a.q_rad, b.q_rad);
  EXPECT_NEAR(a.time_s, p * b.time_s, 1e-12);
  // Over 4000 persons: mean 1 (3 standard errors), the log's std sigma (within 3 %).
  double sum = 0, sum_log = 0, sum_log2 = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    c.seed = 1000 + i;
    const double q = Assistant(model, c).pace();
    sum += q;
    sum_log += std::log(q);
    sum_log2 += std::log(q) * std::log(q);
  }
  const double cv = std::sqrt(std::exp(0.59 * 0.59) - 1);
  EXPECT_NEAR(sum / n, 1.0, 3 * cv / std::sqrt(n));
  const double mean_log = sum_log / n;
  EXPECT_NEAR(std::sqrt(sum_log2 / n - mean_log * mean_log), 0.59, 0.03 * 0.59);
}

// The same seed is the same person making the same choices.
TEST(Assistant, ASeedIsAPerson) {
  const sim::RobotModel model = Model();
  Assistant a(model, AssistantConfig{}), b(model, AssistantConfig{});
  AssistantConfig other;
  other.seed = 2;
  Assistant c(model, other);
  const Viewing view = Overlay(Eigen::Isometry3d::Identity());
  const Eigen::VectorXd q_now = Deg({0, 10, 0, -50, 0, 20, 0}), q_target = Deg({30, 40, -20, -70, 10, 50, 0});
  const double qa = a.Look(1, q_now, q_target, view, kInf).q_rad,
               qb = b.Look(1, q_now, q_target, view, kInf).q_rad;
  EXPECT_EQ(qa, qb);
  EXPECT_NE(a.person_scale(), c.person_scale());
}

}  // namespace
}  // namespace orbed::assistant
