// The emulated set-up assistant's core (assistant.h) on the shipped iiwa 7 model. Oracles: the
// model's geometry (which skeleton points lie on which axis), the iiwa's half-turn identity
// (q_j + 180 deg, -q_j+1 gives the same elbow line), closed-form angles and times.
#include "procs/assistant/assistant.h"

#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
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
  EXPECT_TRUE(file.display_capture_m.isApprox(d.display_capture_m));
  EXPECT_EQ(file.display_noise_arcmin, d.display_noise_arcmin);
  EXPECT_EQ(file.display_depth_fraction_std, d.display_depth_fraction_std);
  EXPECT_EQ(file.display_consult_s, d.display_consult_s);
  EXPECT_EQ(file.rotation_error_base_deg, d.rotation_error_base_deg);
  EXPECT_EQ(file.rotation_error_per_deg, d.rotation_error_per_deg);
  EXPECT_EQ(file.picture_scale_log_sigma, d.picture_scale_log_sigma);
  EXPECT_EQ(file.picture_noise_arcmin, d.picture_noise_arcmin);
  EXPECT_EQ(file.picture_depth_fraction_std, d.picture_depth_fraction_std);
  EXPECT_EQ(file.turn_view_above_deg, d.turn_view_above_deg);
  EXPECT_EQ(file.turn_view_leaves_deg, d.turn_view_leaves_deg);
  EXPECT_EQ(file.view_turn_deg_per_s, d.view_turn_deg_per_s);
  EXPECT_EQ(file.view_zoom_s, d.view_zoom_s);
  EXPECT_EQ(file.choice, d.choice);
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
  // Every new key is checked the same way: its range, NaN, the turn rule's order, the choice's names.
  for (const auto& [text, key] : std::vector<std::pair<std::string, std::string>>{
           {"reflective: {noise_arcmin: .nan}", "assistant.reflective.noise_arcmin"},
           {"reflective: {depth_fraction_std: 0}", "assistant.reflective.depth_fraction_std"},
           {"reflective: {consult_s: -1}", "assistant.reflective.consult_s"},
           {"reflective: {capture_m: [1, .nan, 2]}", "assistant.reflective.capture_m"},
           {"monitor: {rotation_error_base_deg: .inf}", "assistant.monitor.rotation_error_base_deg"},
           {"monitor: {rotation_error_per_deg: -0.1}", "assistant.monitor.rotation_error_per_deg"},
           {"monitor: {turn_view_above_deg: 200}", "assistant.monitor.turn_view_above_deg"},
           {"monitor: {turn_view_above_deg: 30, turn_view_leaves_deg: 40}", "turn_view_leaves_deg"},
           {"monitor: {view_turn_deg_per_s: 0}", "assistant.monitor.view_turn_deg_per_s"},
           {"monitor: {view_zoom_s: .nan}", "assistant.monitor.view_zoom_s"},
           {"acting: {choice: first}", "assistant.acting.choice"}}) {
    try {
      LoadAssistantConfig(write("assistant:\n  " + text + "\n"));
      FAIL() << text << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(LoadAssistantConfig(write("assistant:\n  acting: {choice: best}\n")).choice, Choice::kBest);
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

// The first-order model of assistant.h's file comment, computed from the model's forward
// kinematics and joint axes alone (not from Discrepancy): joint j moved, the others at q_t, the
// hologram displaced by e_p = h_p - r_p. Returns delta_j [rad] (NaN when no point of B_j, B_j+1
// is off the joint's axis: then nothing shows the joint); *bound_rad the stated remainder
// |delta_j| (|delta_j| + max |e_p| / L_min), L_min the smallest lever among the points that carry
// weight (a_p^T W_p a_p at least 1 % of the largest).
double FirstOrderShift(const sim::RobotModel& model, const Assistant& a, int j, const Eigen::VectorXd& q_t,
                       const Viewing& view, double* bound_rad) {
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q_t);
  const int link = model.joints()[j].link;
  const Eigen::Vector3d w = view.X_WR.linear() * X_RL[link].linear() * model.links()[link].axis_J;
  const Eigen::Vector3d o = view.X_WR * X_RL[link].translation();
  const double lateral = a.config().lateral_noise_arcmin / 60 * kDegToRad;
  const double depth = a.config().depth_noise_fraction_std;
  double num = 0, den = 0, e_max = 0;
  std::vector<std::pair<double, double>> levers;  // (a^T W a, |a|)
  for (const Feature& f : a.features(j)) {
    const Eigen::Vector3d r = view.X_WR * (X_RL[f.link] * f.p_L);
    const Eigen::Vector3d e = view.X_WV_seen * (X_RL[f.link] * f.p_L) - r;
    const Eigen::Vector3d a_p = w.cross(r - o);
    const double rho = (r - view.p_WE).norm();
    const Eigen::Vector3d n = (r - view.p_WE) / rho;
    const Eigen::Matrix3d W = (Eigen::Matrix3d::Identity() - n * n.transpose()) / std::pow(rho * lateral, 2) +
                              n * n.transpose() / std::pow(rho * depth, 2);
    num += a_p.dot(W * e);
    den += a_p.dot(W * a_p);
    e_max = std::max(e_max, e.norm());
    levers.emplace_back(a_p.dot(W * a_p), a_p.norm());
  }
  double top = 0, lever_min = kInf;
  for (const auto& l : levers) top = std::max(top, l.first);
  for (const auto& l : levers) {
    if (l.first >= 0.01 * top) lever_min = std::min(lever_min, l.second);
  }
  double lever_max = 0;
  for (const auto& l : levers) lever_max = std::max(lever_max, l.second);
  if (lever_max < 1e-6) return std::nan("");  // the joint moves nothing the person sees
  const double delta = num / den;
  *bound_rad = std::abs(delta) * (std::abs(delta) + e_max / lever_min);
  return delta;
}

// The person compares the real arm with the hologram where it appears: a registration shifted by
// 30 mm, or tilted by 3 deg about a horizontal axis through a point beside the base, moves every
// joint the person sets (others at the target, noises made tiny) by the first-order shift, within
// the stated remainder and half a grid step.
TEST(Assistant, ARegistrationErrorMovesEachJointAsTheFirstOrderModelSays) {
  const sim::RobotModel model = Model();
  const Eigen::VectorXd q_t = Deg({20, 45, -20, -60, 15, 50, 10});
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = 0.03 * Eigen::Vector3d(0.6, -0.64, 0.48);  // |t| = 30 mm
  const Eigen::Vector3d c(0.2, -0.3, 0.1);                         // the tilt's centre [m, W]
  Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
  tilt.linear() = Eigen::AngleAxisd(3 * kDegToRad, Eigen::Vector3d::UnitX()).toRotationMatrix();
  tilt.translation() = c - tilt.linear() * c;
  const double half_step = 0.5 * kGridStepDeg * kDegToRad;
  for (const auto& [name, X_error] :
       {std::make_pair("shift 30 mm", shift), std::make_pair("tilt 3 deg", tilt)}) {
    Viewing view = Overlay(Eigen::Isometry3d::Identity());
    view.X_WV_seen = X_error * view.X_WR;
    int moved = 0;
    for (int j = 0; j < 7; ++j) {
      Assistant a(model, Perfect());
      double bound = 0;
      const double predicted = FirstOrderShift(model, a, j, q_t, view, &bound);
      const double reached = a.Look(j, q_t, q_t, view, kInf).aim_rad - q_t[j];
      if (std::isnan(predicted)) {  // nothing of B_j, B_j+1 is off the axis: no cue, left where it is
        EXPECT_NEAR(reached, 0.0, 1e-12) << name << ", joint " << j + 1;
        continue;
      }
      EXPECT_NEAR(reached, predicted, bound + half_step)
          << name << ", joint " << j + 1 << ": predicted " << predicted * kRadToDeg << " deg, bound "
          << bound * kRadToDeg << " deg";
      if (std::abs(predicted) > bound + half_step) {
        ++moved;
        EXPECT_EQ(reached > 0, predicted > 0) << name << ", joint " << j + 1;
      }
    }
    EXPECT_GE(moved, 3) << name << ": the registration error must move joints for the test to mean anything";
  }
}

// A perfect registration moves nothing: every joint set from the target stays on it (the oracle's
// zero).
TEST(Assistant, APerfectRegistrationLeavesEveryJointOnTheTarget) {
  const sim::RobotModel model = Model();
  const Eigen::VectorXd q_t = Deg({20, 45, -20, -60, 15, 50, 10});
  for (int j = 0; j < 7; ++j) {
    Assistant a(model, Perfect());
    EXPECT_NEAR(a.Look(j, q_t, q_t, Overlay(Eigen::Isometry3d::Identity()), kInf).aim_rad, q_t[j],
                0.5 * kGridStepDeg * kDegToRad + 1e-12)
        << "joint " << j + 1;
  }
}

// The Fisher information of one look at joint j from one viewpoint (the inverse variance of the
// best angle to first order): sum_p a_p^T W_p a_p with the rays from `origin`, from the model's FK
// and joint axes (assistant.h's file comment), at q [rad].
double Information(const sim::RobotModel& model, const Assistant& a, int j, const Eigen::VectorXd& q,
                   const Eigen::Vector3d& origin, double lateral_arcmin, double depth_fraction) {
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q);
  const int link = model.joints()[j].link;
  const Eigen::Vector3d w = X_RL[link].linear() * model.links()[link].axis_J;
  const Eigen::Vector3d o = X_RL[link].translation();
  double info = 0;
  for (const Feature& f : a.features(j)) {
    const Eigen::Vector3d r = X_RL[f.link] * f.p_L;
    const Eigen::Vector3d a_p = w.cross(r - o);
    const double rho = (r - origin).norm();
    const Eigen::Vector3d n = (r - origin) / rho;
    const double along = n.dot(a_p);
    info += (a_p - along * n).squaredNorm() / std::pow(rho * lateral_arcmin / 60 * kDegToRad, 2) +
            along * along / std::pow(rho * depth_fraction, 2);
  }
  return info;
}

// The standard deviation of `looks` aims around `centre` [deg], and their mean [deg].
std::pair<double, double> Spread(const std::vector<double>& aims_rad, double centre_rad) {
  double sum = 0, sum2 = 0;
  for (double x : aims_rad) {
    sum += (x - centre_rad) * kRadToDeg;
    sum2 += std::pow((x - centre_rad) * kRadToDeg, 2);
  }
  const double n = static_cast<double>(aims_rad.size()), mean = sum / n;
  return {std::sqrt(sum2 / n - mean * mean), mean};
}

// A twist seen edge-on: joint 1 turns the bent link 2 along the eye's line of sight, so from the
// eye it shows mostly in depth; the reflective display, captured from beside
// the link, sees the same motion across its rays. Over many seeded looks (best choice, the shipped
// noises, no person scale or hand noise) the aims spread as 1 / sqrt(information) says, from the
// geometry: one view, then both views (the informations add), plus the grid's step^2 / 12; the
// second view lowers the twist's error several fold.
TEST(Assistant, TheReflectiveDisplaysSecondViewpointResolvesATwistSeenEdgeOn) {
  const sim::RobotModel model = Model();
  AssistantConfig c;
  c.user_scale_log_sigma = 0;
  c.placement_noise_deg = 0;
  c.pace_log_sigma = 0;
  c.choice = Choice::kBest;
  // Depth judged 4 times better than the shipped 2 %: one view's error stays small enough for the
  // first-order spread to hold (at 2 % the edge-on twist errs by ~5 deg and the circle's curvature
  // adds lateral cues the linear model does not count).
  c.depth_noise_fraction_std = 0.005;
  const Eigen::VectorXd q_t = Deg({30, 60, 0, -30, 0, 0, 0});
  Eigen::VectorXd q_now = q_t;
  q_now[0] = q_t[0] + 25 * kDegToRad;
  // The elbow (joint 4's place) and the direction it moves as joint 1 turns.
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q_t);
  const Eigen::Vector3d elbow = X_RL[model.joints()[3].link].translation();
  const Eigen::Vector3d radial = Eigen::Vector3d(elbow.x(), elbow.y(), 0).normalized();
  const Eigen::Vector3d tangent = Eigen::Vector3d::UnitZ().cross(radial);
  Viewing view;
  view.mode = orbed::guidance_t::MODE_AR;
  view.p_WE = elbow + 1.8 * tangent;  // looking along the elbow's path
  view.X_WV_display = view.X_WV_seen;
  const Eigen::Vector3d p_WC = elbow + 1.8 * radial;  // looking at it from outside the circle
  const double info_eye = Information(model, Assistant(model, c), 0, q_t, view.p_WE, c.lateral_noise_arcmin,
                                      c.depth_noise_fraction_std);
  const double info_display = Information(model, Assistant(model, c), 0, q_t, p_WC, c.display_noise_arcmin,
                                          c.display_depth_fraction_std);
  const double grid2 = kGridStepDeg * kGridStepDeg / 12;
  const double predicted_one = std::sqrt(std::pow(kRadToDeg, 2) / info_eye + grid2);
  const double predicted_two = std::sqrt(std::pow(kRadToDeg, 2) / (info_eye + info_display) + grid2);
  std::vector<double> one, two;
  for (int seed = 1; seed <= 400; ++seed) {
    c.seed = seed;
    Assistant direct(model, c), reflective(model, c);
    one.push_back(direct.Look(0, q_now, q_t, view, kInf).aim_rad);
    Viewing with_display = view;
    with_display.mode = orbed::guidance_t::MODE_AR_REFLECTIVE;
    with_display.p_WC_display = p_WC;
    two.push_back(reflective.Look(0, q_now, q_t, with_display, kInf).aim_rad);
  }
  const auto [std_one, mean_one] = Spread(one, q_t[0]);
  const auto [std_two, mean_two] = Spread(two, q_t[0]);
  // 400 looks: the std's own standard error is ~3.5 %; 15 % leaves room for the linearisation.
  EXPECT_NEAR(std_one, predicted_one, 0.15 * predicted_one) << "one view";
  EXPECT_NEAR(std_two, predicted_two, 0.15 * predicted_two) << "two views";
  EXPECT_NEAR(mean_one, 0, 4 * predicted_one / std::sqrt(400.0));
  EXPECT_NEAR(mean_two, 0, 4 * predicted_two / std::sqrt(400.0));
  EXPECT_LT(std_two, std_one / 3) << "one view " << std_one << " deg, two " << std_two << " deg";
}

// Consulting the display costs display_consult_s per look, times the pace; without a display (no
// capture viewpoint) ar_reflective is ar.
TEST(Assistant, ConsultingTheDisplayCostsItsTimePerLook) {
  const sim::RobotModel model = Model();
  AssistantConfig c = Perfect();
  c.pace_log_sigma = 0.5;
  Assistant a(model, c);
  Viewing view = Overlay(Eigen::Isometry3d::Identity());
  view.mode = orbed::guidance_t::MODE_AR_REFLECTIVE;
  const Eigen::VectorXd q_now = Deg({0, 0, 0, 0, 0, 0, 0}), q_t = Deg({0, 20, 0, 0, 0, 0, 0});
  EXPECT_NEAR(a.Look(1, q_now, q_t, view, kInf).time_s, a.pace() * c.look_s, 1e-12);
  view.p_WC_display = Eigen::Vector3d(1.45, -1.2, 1.7);
  EXPECT_NEAR(a.Look(1, q_now, q_t, view, kInf).time_s, a.pace() * (c.look_s + c.display_consult_s), 1e-12);
}

// The display's viewpoint in assistant.yaml is where orbed-hmd captures display 0: hmd.yaml names
// its waypoint, viraal_walk.yaml places it (the head's place; the PV camera is a few cm from it).
TEST(Assistant, TheDisplaysViewpointIsWhereTheHeadsetCapturesIt) {
  const YAML::Node hmd = YAML::LoadFile(SourceTreePath("hmd_emulator/config/hmd.yaml"));
  const YAML::Node walk = YAML::LoadFile(SourceTreePath("hmd_emulator/config/viraal_walk.yaml"));
  const std::string waypoint = hmd["hmd"]["displays"][0]["capture_waypoint"].as<std::string>();
  std::optional<Eigen::Vector3d> p;
  for (const YAML::Node& w : walk["head_trajectory"]["waypoints"]) {
    if (w["name"].as<std::string>() != waypoint) continue;
    const auto v = w["position_m"].as<std::vector<double>>();
    p = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  ASSERT_TRUE(p.has_value()) << "waypoint " << waypoint;
  const AssistantConfig file = LoadAssistantConfig(SourceTreePath(kDefaultConfigRelativePath));
  EXPECT_LT((file.display_capture_m - *p).norm(), 1e-9) << waypoint;
}

// On the fixed monitor, with the picture read exactly but turned into one's view with a heading
// error, joint 1 (link 2 bent) is off by that error: over many looks its spread is sigma_rot(theta)
// = base + per_deg * theta, larger at a larger angle between the monitor's camera and the eye; the
// time per look is look_s + theta / mental_rotation_deg_per_s.
TEST(Assistant, ALargerMonitorAngleRaisesTheErrorAndTheTime) {
  const sim::RobotModel model = Model();
  AssistantConfig c = Perfect();
  c.rotation_error_base_deg = 3.0;
  c.rotation_error_per_deg = 0.15;
  c.choice = Choice::kBest;
  const Eigen::VectorXd q_t = Deg({20, 60, 0, -30, 0, 0, 0});
  Eigen::VectorXd q_now = q_t;
  q_now[0] = 0;
  Viewing view = Overlay(Eigen::Isometry3d::Identity());
  view.mode = orbed::guidance_t::MODE_FIXED_DISPLAY;
  view.p_WE = Eigen::Vector3d(2.0, 0, 1.6);
  double last_std = 0;
  for (double theta : {30.0, 120.0}) {
    view.p_WD = Eigen::Vector3d(2.0 * std::cos(theta * kDegToRad), 2.0 * std::sin(theta * kDegToRad), 1.8);
    std::vector<double> aims;
    double time_s = 0;
    for (int seed = 1; seed <= 400; ++seed) {
      c.seed = seed;
      Assistant a(model, c);
      const JointLook look = a.Look(0, q_now, q_t, view, kInf);
      aims.push_back(look.aim_rad);
      time_s = look.time_s;
    }
    Assistant a(model, c);
    ASSERT_NEAR(a.MonitorDisparityDeg(view), theta, 1e-9);
    const double sigma = c.rotation_error_base_deg + c.rotation_error_per_deg * theta;
    const auto [std_deg, mean_deg] = Spread(aims, q_t[0]);
    EXPECT_NEAR(std_deg, sigma, 0.1 * sigma) << "theta " << theta;
    EXPECT_NEAR(mean_deg, 0, 4 * sigma / std::sqrt(400.0)) << "theta " << theta;
    EXPECT_GT(std_deg, last_std);
    EXPECT_NEAR(time_s, c.look_s + theta / c.mental_rotation_deg_per_s, 1e-12);
    last_std = std_deg;
  }
}

// The person turns a monitor's view that is more than turn_view_above_deg from their own until
// turn_view_leaves_deg is left, and zooms a camera farther than their eye in to the eye's distance:
// the error falls to sigma_rot(leaves), the turn costs (turned / view_turn_deg_per_s + view_zoom_s)
// times the pace; a view within the threshold is left as it is.
TEST(Assistant, TurningTheMonitorsViewLowersTheErrorAndCostsTime) {
  const sim::RobotModel model = Model();
  AssistantConfig c = Perfect();
  c.pace_log_sigma = 0.4;
  c.rotation_error_base_deg = 3.0;
  c.rotation_error_per_deg = 0.15;
  Assistant a(model, c);
  Viewing view = Overlay(Eigen::Isometry3d::Identity());
  view.mode = orbed::guidance_t::MODE_FIXED_DISPLAY;
  view.p_WE = Eigen::Vector3d(2.0, 0, 1.0);  // 2.24 m from the base
  const double theta = 120.0;
  view.p_WD = Eigen::Vector3d(3.0 * std::cos(theta * kDegToRad), 3.0 * std::sin(theta * kDegToRad), 1.5);
  const MonitorTurn turn = a.PlanMonitorView(view);
  EXPECT_NEAR(turn.turned_deg, theta - c.turn_view_leaves_deg, 1e-9);
  EXPECT_TRUE(turn.zoomed);
  EXPECT_NEAR(turn.p_WD.norm(), view.p_WE.norm(), 1e-9);
  EXPECT_NEAR(turn.time_s,
              a.pace() * ((theta - c.turn_view_leaves_deg) / c.view_turn_deg_per_s + c.view_zoom_s), 1e-12);
  Viewing turned = view;
  turned.p_WD = turn.p_WD;
  EXPECT_NEAR(a.MonitorDisparityDeg(turned), c.turn_view_leaves_deg, 1e-9);
  EXPECT_LT(a.RotationErrorStdDeg(a.MonitorDisparityDeg(turned)), a.RotationErrorStdDeg(theta));
  // Turned the other way round too: towards the eye, whichever side the camera is on.
  view.p_WD = Eigen::Vector3d(3.0 * std::cos(theta * kDegToRad), -3.0 * std::sin(theta * kDegToRad), 1.5);
  turned.p_WD = a.PlanMonitorView(view).p_WD;
  EXPECT_NEAR(a.MonitorDisparityDeg(turned), c.turn_view_leaves_deg, 1e-9);
  // Within the threshold and nearer than the eye: nothing to do.
  view.p_WD = Eigen::Vector3d(1.5 * std::cos(30 * kDegToRad), 1.5 * std::sin(30 * kDegToRad), 0.8);
  const MonitorTurn none = a.PlanMonitorView(view);
  EXPECT_EQ(none.turned_deg, 0.0);
  EXPECT_FALSE(none.zoomed);
  EXPECT_EQ(none.time_s, 0.0);
  EXPECT_TRUE(none.p_WD.isApprox(*view.p_WD));
}

// A half-turn ambiguity: link 2 bent level with the eye and pointing straight away from it, so
// joint 1 at the target and half a turn from it differ only in depth (the link pointing away or
// towards the eye). For a person who judges depth poorly both look right (two ranges); starting
// nearer the half turn, `nearest` turns to the edge of its range, `best` to the target, whose
// discrepancy is lower by
// the depth term S = sum_p (2 L_p)^2 / (rho_p sigma_depth)^2 (L_p the point's lever), computed
// from the geometry (within the margin, well above the noise's spread 2 sqrt(S)).
TEST(Assistant, TheChoiceRuleDecidesAHalfTurnAmbiguity) {
  const sim::RobotModel model = Model();
  AssistantConfig c;
  c.user_scale_log_sigma = 0;
  c.placement_noise_deg = 0;
  c.pace_log_sigma = 0;
  c.depth_noise_fraction_std = 0.016;
  c.match_margin = 200;
  const Eigen::VectorXd q_t = Deg({90, 90, 0, 0, 0, 0, 0});
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q_t);
  const Eigen::Vector3d elbow = X_RL[model.joints()[3].link].translation();
  const Eigen::Vector3d shoulder = X_RL[model.joints()[1].link].translation();
  Viewing view = Overlay(Eigen::Isometry3d::Identity());
  // On the link's line, behind the shoulder, at its height.
  view.p_WE = shoulder - 2.5 * (elbow - shoulder).normalized();
  double S = 0;
  const Assistant person(model, c);
  for (const Feature& f : person.features(0)) {
    const Eigen::Vector3d r = X_RL[f.link] * f.p_L;
    const double lever = Eigen::Vector2d(r.x(), r.y()).norm();
    S += std::pow(2 * lever / ((r - view.p_WE).norm() * c.depth_noise_fraction_std), 2);
  }
  ASSERT_GT(S, 4 * 2 * std::sqrt(S)) << "S " << S;                   // the target's lead over the noise
  ASSERT_LT(S + 4 * 2 * std::sqrt(S), c.match_margin) << "S " << S;  // the half turn looks right
  // The half turn's range is where its D is within margin of the target's minimum: half-width
  // sqrt((margin - S) / information), S within 4 standard deviations (2 sqrt(S) each); its centre
  // spreads by 1 / sqrt(information) [deg].
  const double info =
      Information(model, person, 0, q_t, view.p_WE, c.lateral_noise_arcmin, c.depth_noise_fraction_std);
  const double widest = std::sqrt((c.match_margin - S + 8 * std::sqrt(S)) / info) * kRadToDeg;
  const double spread = kRadToDeg / std::sqrt(info);
  Eigen::VectorXd q_now = q_t;
  q_now[0] = -60 * kDegToRad;  // 30 deg from the half turn (-90), 150 from the target
  for (int seed = 1; seed <= 10; ++seed) {
    c.seed = seed;
    c.choice = Choice::kNearest;
    Assistant nearest(model, c);
    c.choice = Choice::kBest;
    Assistant best(model, c);
    const JointLook a = nearest.Look(0, q_now, q_t, view, kInf), b = best.Look(0, q_now, q_t, view, kInf);
    EXPECT_EQ(a.ranges, 2) << "seed " << seed;
    // nearest: in the half turn's range, on its side towards q_now; best: the target.
    EXPECT_GT(a.aim_rad * kRadToDeg, -90.0 - 4 * spread - kGridStepDeg) << "seed " << seed;
    EXPECT_LT(a.aim_rad * kRadToDeg, -90.0 + widest + 4 * spread + kGridStepDeg) << "seed " << seed;
    EXPECT_NEAR(b.aim_rad * kRadToDeg, 90.0, 4 * spread + kGridStepDeg) << "seed " << seed;
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
