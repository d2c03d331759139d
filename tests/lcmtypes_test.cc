// The message contract: orbed's iiwa types are wire-compatible with Drake's (same LCM
// fingerprint, and bytes written by one decode as the other), and every type round-trips.
#include <gtest/gtest.h>
#include <drake/lcmt_iiwa_command.hpp>
#include <drake/lcmt_iiwa_status.hpp>
#include <orbed/all_types.hpp>

namespace {

TEST(LcmTypes, IiwaStatusFingerprintEqualsDrakes) {
  EXPECT_EQ(orbed::iiwa_status_t::getHash(), drake::lcmt_iiwa_status::getHash());
  orbed::iiwa_status_t ours{};
  ours.utime = 123456789;
  ours.num_joints = 7;
  std::vector<double> q = {0.1, -0.2, 0.3, -0.4, 0.5, -0.6, 0.7};
  ours.joint_position_measured = q;
  ours.joint_velocity_estimated.assign(7, 0.01);
  ours.joint_position_commanded = q;
  ours.joint_position_ipo = q;
  ours.joint_torque_measured.assign(7, 1.5);
  ours.joint_torque_commanded.assign(7, 2.5);
  ours.joint_torque_external.assign(7, -3.5);
  std::vector<uint8_t> bytes(ours.getEncodedSize());
  ASSERT_EQ(ours.encode(bytes.data(), 0, bytes.size()), static_cast<int>(bytes.size()));
  drake::lcmt_iiwa_status theirs;
  ASSERT_EQ(theirs.decode(bytes.data(), 0, bytes.size()), static_cast<int>(bytes.size()));
  EXPECT_EQ(theirs.utime, 123456789);
  EXPECT_EQ(theirs.joint_position_measured, q);
  EXPECT_EQ(theirs.joint_torque_external[6], -3.5);
}

TEST(LcmTypes, IiwaCommandFingerprintEqualsDrakes) {
  EXPECT_EQ(orbed::iiwa_command_t::getHash(), drake::lcmt_iiwa_command::getHash());
  drake::lcmt_iiwa_command theirs{};
  theirs.utime = 42;
  theirs.num_joints = 7;
  theirs.joint_position = {1, 2, 3, 4, 5, 6, 7};
  theirs.num_torques = 0;
  std::vector<uint8_t> bytes(theirs.getEncodedSize());
  theirs.encode(bytes.data(), 0, bytes.size());
  orbed::iiwa_command_t ours;
  ASSERT_EQ(ours.decode(bytes.data(), 0, bytes.size()), static_cast<int>(bytes.size()));
  EXPECT_EQ(ours.joint_position, theirs.joint_position);
  EXPECT_EQ(ours.num_torques, 0);
}

// A different field order or name must change the fingerprint (the test above could not pass
// by accident): Drake's status vs our command.
TEST(LcmTypes, FingerprintsDifferAcrossTypes) {
  EXPECT_NE(orbed::iiwa_status_t::getHash(), orbed::iiwa_command_t::getHash());
}

template <class T>
void ExpectDefaultRoundTrip(const char* name) {
  T msg{};
  std::vector<uint8_t> bytes(msg.getEncodedSize());
  ASSERT_EQ(msg.encode(bytes.data(), 0, bytes.size()), static_cast<int>(bytes.size())) << name;
  T back;
  EXPECT_EQ(back.decode(bytes.data(), 0, bytes.size()), static_cast<int>(bytes.size())) << name;
  EXPECT_EQ(std::string(T::getTypeName()), name);
}

TEST(LcmTypes, EveryTypeRoundTripsAndHasAUniqueFingerprint) {
  std::map<int64_t, std::string> seen;
  int count = 0;
#define ORBED_CHECK(type)                                                   \
  ExpectDefaultRoundTrip<orbed::type>(#type);                               \
  EXPECT_TRUE(seen.emplace(orbed::type::getHash(), #type).second) << #type; \
  ++count;
  ORBED_FOR_EACH_LCM_TYPE(ORBED_CHECK)
#undef ORBED_CHECK
  EXPECT_GE(count, 20);
}

}  // namespace
