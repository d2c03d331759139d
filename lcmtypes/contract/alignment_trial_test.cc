// The one ALIGNMENT_TRIAL check: each rule of the contract by a hand-built message.
#include "lcmtypes/contract/alignment_trial.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace orbed {
namespace {

using AT = orbed::alignment_trial_t;

AT Good() {
  AT msg{};
  msg.session_id = "run-ar_reflective";
  msg.trial_index = 2;
  msg.display_mode = AT::MODE_AR_REFLECTIVE;
  msg.num_mirrors = 1;
  msg.num_joints = 7;
  msg.joint_position = {0, 0.5, 0, -1, 0, 0.8, 0};
  msg.X_WV.position_m[0] = 0.25;
  msg.X_WV.quaternion_wxyz[0] = std::sqrt(0.5);
  msg.X_WV.quaternion_wxyz[3] = std::sqrt(0.5);  // 90 deg about z
  msg.duration_s = 41.5;
  return msg;
}

std::string Key(const AT& msg) {
  const auto checked = CheckAlignmentTrial(msg, 64);
  const auto* refusal = std::get_if<Refusal>(&checked);
  if (refusal == nullptr) return "";
  EXPECT_FALSE(refusal->reason.empty());
  return refusal->key;
}

TEST(AlignmentTrial, AValidTrialIsDecoded) {
  const auto checked = CheckAlignmentTrial(Good(), 64);
  ASSERT_TRUE(std::holds_alternative<AlignmentTrial>(checked));
  const AlignmentTrial& t = std::get<AlignmentTrial>(checked);
  EXPECT_EQ(t.q_rad.size(), 7);
  EXPECT_DOUBLE_EQ(t.q_rad[5], 0.8);
  EXPECT_NEAR(t.X_WV.translation().x(), 0.25, 1e-15);
  // 90 deg about z: x of V is y of W.
  EXPECT_NEAR((t.X_WV.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0, 1e-12);
}

TEST(AlignmentTrial, EachRuleRefusesByFieldName) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  AT m = Good();
  m.session_id = "";
  EXPECT_EQ(Key(m), "session_id");
  m = Good();
  m.trial_index = -1;
  EXPECT_EQ(Key(m), "trial_index");
  m.trial_index = kMaxTrialsPerSession;  // one beyond the last a session holds
  EXPECT_EQ(Key(m), "trial_index");
  m.trial_index = kMaxTrialsPerSession - 1;
  EXPECT_EQ(Key(m), "");
  m = Good();
  m.display_mode = 2;
  EXPECT_EQ(Key(m), "display_mode");
  m = Good();
  m.display_mode = AT::MODE_AR;  // with one mirror
  EXPECT_EQ(Key(m), "num_mirrors");
  m.num_mirrors = 0;
  EXPECT_EQ(Key(m), "");
  m = Good();
  m.num_joints = 6;  // the array holds 7
  EXPECT_EQ(Key(m), "num_joints");
  m = Good();
  m.num_joints = 65;
  m.joint_position.assign(65, 0.0);
  EXPECT_EQ(Key(m), "num_joints");  // beyond max_joints
  m = Good();
  m.joint_position[3] = nan;
  EXPECT_EQ(Key(m), "joint_position");
  m = Good();
  m.X_WV.quaternion_wxyz[0] = 1.0;  // norm sqrt(1.5)
  EXPECT_EQ(Key(m), "X_WV");
  m = Good();
  m.X_WV.position_m[2] = 2e4;  // finite, not an operating room
  EXPECT_EQ(Key(m), "X_WV");
  m = Good();
  m.duration_s = -0.1;
  EXPECT_EQ(Key(m), "duration_s");
  m.duration_s = INFINITY;
  EXPECT_EQ(Key(m), "duration_s");
}

// Contract change 2: the tracking faults the user met, the wait part of duration_s.
TEST(AlignmentTrial, TrackingFaults) {
  AT m = Good();
  m.tracking_losses = 2;
  m.relocalizations = 2;
  m.tracking_wait_s = 3.5;
  m.alignment_repeats = 1;
  EXPECT_EQ(Key(m), "");
  m.tracking_wait_s = m.duration_s;
  EXPECT_EQ(Key(m), "");
  m.tracking_wait_s = m.duration_s + 0.1;  // waited longer than the whole trial
  EXPECT_EQ(Key(m), "tracking_faults");
  m.tracking_wait_s = NAN;
  EXPECT_EQ(Key(m), "tracking_faults");
  m = Good();
  m.tracking_wait_s = -1;
  EXPECT_EQ(Key(m), "tracking_faults");
  for (int32_t AT::*field : {&AT::tracking_losses, &AT::relocalizations, &AT::alignment_repeats}) {
    m = Good();
    m.*field = -1;
    EXPECT_EQ(Key(m), "tracking_faults");
  }
}

// Contract change 5: the landmark annotation. Good() with two landmarks, two rays per side each.
AT Annotated() {
  AT m = Good();
  for (int l = 0; l < 2; ++l) {
    for (int8_t side : {AT::ANNOTATION_REAL, AT::ANNOTATION_VIRTUAL}) {
      for (int k = 0; k < 2; ++k) {
        m.annotation_landmark.push_back(l);
        m.annotation_side.push_back(side);
        m.annotation_origin_W_m.push_back({0.3 * k, 0.0, 1.6});
        m.annotation_direction_W.push_back({0.0, 0.6, -0.8});
      }
    }
  }
  m.num_annotation_rays = static_cast<int32_t>(m.annotation_landmark.size());
  return m;
}

TEST(AlignmentTrial, AnnotationIsDecodedByLandmarkAndSide) {
  const auto checked = CheckAlignmentTrial(Annotated(), 64);
  ASSERT_TRUE(std::holds_alternative<AlignmentTrial>(checked));
  const AlignmentTrial& t = std::get<AlignmentTrial>(checked);
  ASSERT_EQ(t.annotation.size(), 2u);
  for (const auto& landmark : t.annotation) {
    for (const LandmarkRays& rays : landmark) {
      ASSERT_EQ(rays.origin_W_m.size(), 2u);
      EXPECT_EQ(rays.origin_W_m[1], Eigen::Vector3d(0.3, 0.0, 1.6));
      EXPECT_EQ(rays.direction_W[0], Eigen::Vector3d(0.0, 0.6, -0.8));
    }
  }
  EXPECT_TRUE(std::get<AlignmentTrial>(CheckAlignmentTrial(Good(), 64)).annotation.empty());
}

TEST(AlignmentTrial, AnnotationRules) {
  AT m = Annotated();
  m.num_annotation_rays = 7;  // the arrays hold 8
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_side.pop_back();  // one array shorter than the count
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_landmark[0] = 16;
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_landmark[0] = -1;
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_side[0] = 2;
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_origin_W_m[3][1] = NAN;
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_origin_W_m[3][1] = 2e4;  // not in an operating room
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_direction_W[5] = {0.0, 0.0, 1.01};  // not a unit vector
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_direction_W[5] = {0.0, 0.0, INFINITY};
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_origin_W_m[5] = {0.0, 0.0};  // a row of two values
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.annotation_landmark[7] = 3;  // landmark 1 left with one virtual ray, landmarks 2 and 3 with one
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  for (int k = 4; k < 8; ++k) m.annotation_landmark[k] = 2;  // landmark 1 has none
  EXPECT_EQ(Key(m), "annotation");
  m = Annotated();
  m.num_annotation_rays = kMaxAnnotationRays + 1;
  m.annotation_landmark.assign(m.num_annotation_rays, 0);
  m.annotation_side.assign(m.num_annotation_rays, +AT::ANNOTATION_REAL);
  m.annotation_origin_W_m.assign(m.num_annotation_rays, {0, 0, 1});
  m.annotation_direction_W.assign(m.num_annotation_rays, {1, 0, 0});
  EXPECT_EQ(Key(m), "annotation");
}

}  // namespace
}  // namespace orbed
