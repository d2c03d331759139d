// The message contract: orbed's iiwa types are wire-compatible with Drake's (same LCM
// fingerprint, and bytes written by one decode as the other), every type round-trips, and every
// type's fingerprint is pinned, so that no change of the contract passes unnoticed.
#include <gtest/gtest.h>
#include <cstdio>
#include <drake/lcmt_iiwa_command.hpp>
#include <drake/lcmt_iiwa_status.hpp>
#include <drake/lcmt_viewer_draw.hpp>
#include <drake/lcmt_viewer_load_robot.hpp>
#include <map>
#include <orbed/all_types.hpp>
#include <string>

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

// Drake's viewer types (Meldis, drake-visualizer): the same fingerprints, and a draw message
// written by one decodes as the other with the same values.
TEST(LcmTypes, ViewerTypesAreDrakes) {
  EXPECT_EQ(orbed::viewer_geometry_data_t::getHash(), drake::lcmt_viewer_geometry_data::getHash());
  EXPECT_EQ(orbed::viewer_link_data_t::getHash(), drake::lcmt_viewer_link_data::getHash());
  EXPECT_EQ(orbed::viewer_load_robot_t::getHash(), drake::lcmt_viewer_load_robot::getHash());
  EXPECT_EQ(orbed::viewer_draw_t::getHash(), drake::lcmt_viewer_draw::getHash());
  orbed::viewer_load_robot_t load{};
  orbed::viewer_link_data_t link{};
  link.name = "iiwa_link_2";
  link.robot_num = 1;
  orbed::viewer_geometry_data_t g{};
  g.type = orbed::viewer_geometry_data_t::CYLINDER;
  g.quaternion[0] = 1;
  g.color[3] = 0.5f;
  g.num_float_data = 2;
  g.float_data = {0.07f, 0.11f};
  link.num_geom = 1;
  link.geom.push_back(g);
  load.num_links = 1;
  load.link.push_back(link);
  std::vector<uint8_t> bytes(load.getEncodedSize());
  ASSERT_EQ(load.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  drake::lcmt_viewer_load_robot theirs;
  ASSERT_EQ(theirs.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  ASSERT_EQ(theirs.link.size(), 1u);
  EXPECT_EQ(theirs.link[0].name, "iiwa_link_2");
  EXPECT_EQ(theirs.link[0].geom[0].type, int{drake::lcmt_viewer_geometry_data::CYLINDER});
  EXPECT_EQ(theirs.link[0].geom[0].float_data[1], 0.11f);
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

// LCM's fingerprint covers every field's name, type and order, and a receiver refuses bytes with
// another fingerprint ("<channel>/decode/fingerprint"): any change of a type is a breaking change
// on the wire. docs/design.md §3 "Changing the contract" says how one is made: fields appended at the
// end, the change listed there with the old and new fingerprints, and this table updated in the same
// commit. Last change: contract change 11 (hologram_scene_t added, the holograms a client placed
// through hl2ss); before it, contract change 10 (run_dir appended to deputy_command_t, the last lines of
// output to deputy_child_t and so deputy_status_t); before it, contract change 9 (host appended to
// process_status_t; the four deputy_*_t types of launch across hosts); before it, contract change 8
// (lockstep_round appended to sim_clock_t, sim_clock_ack_t added); contract change 5 (the landmark annotation
// appended to alignment_trial_t); before it, contract change 4 (types added: setup_task_t and setup_result_t
// for the robot set-up study, the four viewer_*_t types that are Drake's lcmt_viewer_*); before it, contract
// change 3 (dropped, drop_reason and drop_count appended to process_status_t); before it, contract change 2
// (the tracking fault record appended to alignment_trial_t) and contract change 1 (request_id appended to
// session_control_t, alignment_trial_t and registration_t).
TEST(LcmTypes, FingerprintsArePinned) {
  const std::map<std::string, uint64_t> pinned = {{"alignment_trial_t", 0x271026afe7973c6dULL},
                                                  {"collision_status_t", 0x9f78934234cce93fULL},
                                                  {"contact_t", 0x2d8c8a472f48e7e9ULL},
                                                  {"deputy_child_t", 0x650aa07106b4aaadULL},
                                                  {"deputy_command_t", 0x4dd7cfc5439ab4c1ULL},
                                                  {"deputy_process_t", 0xea93be0d0e14b1f6ULL},
                                                  {"deputy_status_t", 0xa046332a3108edd5ULL},
                                                  {"gaze_ray_t", 0x65a37e31d5a2eea1ULL},
                                                  {"guidance_t", 0x00fc655bb50b4853ULL},
                                                  {"hmd_pose_t", 0xdafcd85796f0e809ULL},
                                                  {"hologram_scene_t", 0xb7ba7ed6390181d1ULL},
                                                  {"iiwa_command_t", 0xddc7c7738c815334ULL},
                                                  {"iiwa_status_t", 0xf16fb804284abca3ULL},
                                                  {"image_t", 0xc1d60fc65b87f013ULL},
                                                  {"landmark_request_t", 0x3188225146589311ULL},
                                                  {"landmark_t", 0xf3c71cad48c8b4fdULL},
                                                  {"logger_status_t", 0xfd805aae7883ea7bULL},
                                                  {"misalignment_request_t", 0x9814e62c0e8405c3ULL},
                                                  {"misalignment_t", 0x62c181d75e5aaae9ULL},
                                                  {"plan_check_reply_t", 0x08220670e46ad680ULL},
                                                  {"plan_check_request_t", 0xf954868fc0afdd74ULL},
                                                  {"pose_t", 0xcefe2d89aeb7c79fULL},
                                                  {"process_status_t", 0xfc07aa15bec7ef20ULL},
                                                  {"reflective_view_t", 0xba9d743e2da58034ULL},
                                                  {"registration_t", 0xa59c0b3d053d0d83ULL},
                                                  {"robot_state_t", 0x3af0ecdeab2a6837ULL},
                                                  {"session_control_t", 0x875cddac9b006a4fULL},
                                                  {"setup_result_t", 0x7b1a0cab822c59c1ULL},
                                                  {"setup_task_t", 0x45ebcc451fbad1b9ULL},
                                                  {"sim_clock_ack_t", 0x9f69f92cf9789595ULL},
                                                  {"sim_clock_t", 0xc43966af39ba4bf2ULL},
                                                  {"target_pose_t", 0x861ba235288a4402ULL},
                                                  {"viewer_draw_t", 0x414f0bfe5b2f4244ULL},
                                                  {"viewer_geometry_data_t", 0x5d2e34cb3257db07ULL},
                                                  {"viewer_link_data_t", 0x51252725af982a63ULL},
                                                  {"viewer_load_robot_t", 0x8987209b10aa2d39ULL}};
  std::map<std::string, uint64_t> actual;
#define ORBED_HASH(type) actual[#type] = static_cast<uint64_t>(orbed::type::getHash());
  ORBED_FOR_EACH_LCM_TYPE(ORBED_HASH)
#undef ORBED_HASH
  auto hex = [](uint64_t v) {
    char text[32];
    std::snprintf(text, sizeof(text), "0x%016llx", static_cast<unsigned long long>(v));
    return std::string(text);
  };
  EXPECT_EQ(actual.size(), pinned.size()) << "a type was added or removed: pin it (docs/design.md §3)";
  for (const auto& [type, hash] : actual) {
    const auto it = pinned.find(type);
    ASSERT_NE(it, pinned.end()) << type << " is not pinned (its fingerprint is " << hex(hash) << ")";
    EXPECT_EQ(hex(hash), hex(it->second))
        << type << " changed: follow docs/design.md §3, Changing the contract";
  }
}

}  // namespace
