// The one check of each single-reader request and command: valid messages decode, each rule
// refuses by its key.
#include "lcmtypes/contract/requests.h"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace orbed {
namespace {

template <class T, class V>
std::string Key(const V& checked) {
  if (std::holds_alternative<T>(checked)) return "";
  return std::get<Refusal>(checked).key;
}

// ROBOT_STATE: every field out of its contract is named (a count that disagrees with its array, the
// arm's joint count, NaN, a bad quaternion, an unknown motion state, too many links).
TEST(Requests, RobotState) {
  orbed::robot_state_t good{};
  good.X_WR.quaternion_wxyz[0] = 1;
  good.num_joints = 7;
  good.joint_position.assign(7, 0.1);
  good.joint_limit_hit.assign(7, 0);
  EXPECT_EQ(CheckRobotState(good, 7), "");
  auto reason = [&](auto mutate) {
    orbed::robot_state_t m = good;
    mutate(m);
    return CheckRobotState(m, 7);
  };
  EXPECT_NE(reason([](auto& m) { m.num_joints = 6; }).find("num_joints"), std::string::npos);
  EXPECT_NE(reason([](auto& m) { m.joint_limit_hit.pop_back(); }).find("joint_limit_hit"), std::string::npos);
  EXPECT_NE(reason([](auto& m) { m.joint_position[2] = std::nan(""); }).find("joint_position"),
            std::string::npos);
  EXPECT_NE(reason([](auto& m) { m.X_WR.quaternion_wxyz[0] = 0.5; }).find("X_WR"), std::string::npos);
  EXPECT_NE(reason([](auto& m) { m.motion_state = 9; }).find("motion_state"), std::string::npos);
  // A base beyond 10 km of the world origin is no place (and would overflow a renderer's floats).
  EXPECT_EQ(reason([](auto& m) { m.X_WR.position_m[1] = -9999.0; }), "");
  EXPECT_NE(reason([](auto& m) {
              m.X_WR.position_m[0] = 6000;
              m.X_WR.position_m[1] = 8000.1;
            }).find("beyond 10000 m"),
            std::string::npos);
  EXPECT_NE(reason([](auto& m) { m.X_WR.position_m[2] = 2e38; }).find("X_WR.position_m"), std::string::npos);
  EXPECT_NE(reason([](auto& m) { m.num_links = 1; }).find("num_links"), std::string::npos);
  EXPECT_NE(reason([](auto& m) {
              m.num_links = kMaxRobotStateLinks + 1;
              m.X_RL.resize(m.num_links);
              m.link_names.assign(m.num_links, "l");
            }).find("num_links"),
            std::string::npos);
}

// COLLISION_STATUS: +inf (nothing checked) passes; NaN, −inf and counts that disagree are named.
TEST(Requests, CollisionStatus) {
  orbed::collision_status_t good{};
  good.min_distance_m = 0.12;
  good.num_links = 2;
  good.link_names = {"a", "b"};
  good.link_clearance_m = {0.12, 0.3};
  EXPECT_EQ(CheckCollisionStatus(good), "");
  orbed::collision_status_t m = good;
  m.min_distance_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(CheckCollisionStatus(m), "");
  m.min_distance_m = -std::numeric_limits<double>::infinity();
  EXPECT_NE(CheckCollisionStatus(m).find("min_distance_m"), std::string::npos);
  m.min_distance_m = std::nan("");
  EXPECT_NE(CheckCollisionStatus(m).find("min_distance_m"), std::string::npos);
  m = good;
  m.num_contacts = 1;
  EXPECT_NE(CheckCollisionStatus(m).find("num_contacts"), std::string::npos);
  m = good;
  m.link_clearance_m.pop_back();
  EXPECT_NE(CheckCollisionStatus(m).find("link_clearance_m"), std::string::npos);
}

TEST(Requests, IiwaCommand) {
  orbed::iiwa_command_t m{};
  m.utime = 5;
  m.num_joints = 7;
  m.joint_position = {0, 0.1, 0, -1, 0, 0.5, 0};
  const auto ok = CheckIiwaCommand(m, 7);
  ASSERT_TRUE(std::holds_alternative<IiwaCommand>(ok));
  EXPECT_DOUBLE_EQ(std::get<IiwaCommand>(ok).q_rad[3], -1.0);
  EXPECT_EQ(std::get<IiwaCommand>(ok).utime, 5);
  EXPECT_EQ(Key<IiwaCommand>(CheckIiwaCommand(m, 6)), "num_joints");
  orbed::iiwa_command_t t = m;
  t.num_torques = 3;
  t.joint_torque = {1, 2, 3};
  EXPECT_EQ(Key<IiwaCommand>(CheckIiwaCommand(t, 7)), "num_torques");
  t.num_torques = 7;
  t.joint_torque.assign(7, 0.0);
  EXPECT_EQ(Key<IiwaCommand>(CheckIiwaCommand(t, 7)), "");
  t.joint_torque[2] = NAN;
  EXPECT_EQ(Key<IiwaCommand>(CheckIiwaCommand(t, 7)), "non_finite");
  m.joint_position[0] = INFINITY;
  EXPECT_EQ(Key<IiwaCommand>(CheckIiwaCommand(m, 7)), "non_finite");
}

TEST(Requests, PlanCheckRequest) {
  orbed::plan_check_request_t m{};
  m.request_id = 42;
  m.num_joints = 7;
  m.joint_position.assign(7, 0.2);
  const auto ok = CheckPlanCheckRequest(m, 7);
  ASSERT_TRUE(std::holds_alternative<PlanCheckRequest>(ok));
  EXPECT_EQ(std::get<PlanCheckRequest>(ok).request_id, 42);
  EXPECT_EQ(Key<PlanCheckRequest>(CheckPlanCheckRequest(m, 8)), "num_joints");
  m.joint_position[6] = NAN;
  EXPECT_EQ(Key<PlanCheckRequest>(CheckPlanCheckRequest(m, 7)), "non_finite");
}

TEST(Requests, LandmarkAndMisalignmentRows) {
  orbed::landmark_request_t l{};
  l.num_rays = 2;
  l.origin_W_m = {{0, 0, 1}, {1, 0, 1}};
  l.direction_W = {{1, 0, 0}, {0, 1, 0}};
  const auto ok = CheckLandmarkRequest(l, 10);
  ASSERT_TRUE(std::holds_alternative<LandmarkRequest>(ok));
  EXPECT_EQ(std::get<LandmarkRequest>(ok).origin_W_m[1], Eigen::Vector3d(1, 0, 1));
  EXPECT_EQ(Key<LandmarkRequest>(CheckLandmarkRequest(l, 1)), "invalid");  // beyond max_rays
  l.direction_W[1] = {0, 2e4, 0};                                          // finite, not an operating room
  EXPECT_EQ(Key<LandmarkRequest>(CheckLandmarkRequest(l, 10)), "invalid");
  orbed::misalignment_request_t m{};
  m.num_pairs = 1;
  m.p_W_real_m = {{0, 0, 0}};
  m.p_W_virtual_m = {{0, 0, 0.01}};
  EXPECT_EQ(Key<MisalignmentRequest>(CheckMisalignmentRequest(m, 10)), "");
  m.num_pairs = 2;  // the arrays hold one pair
  EXPECT_EQ(Key<MisalignmentRequest>(CheckMisalignmentRequest(m, 10)), "invalid");
  m.num_pairs = 1;
  m.p_W_virtual_m = {{0, NAN, 0}};
  EXPECT_EQ(Key<MisalignmentRequest>(CheckMisalignmentRequest(m, 10)), "invalid");
}

}  // namespace
}  // namespace orbed
