// orbed-log export --mcap on a log whose messages are known by construction, read back by an
// independent reader: @mcap/core's McapIndexedReader under node (mcap/mcap_export.test.mjs says what
// it checks: the summary and the indexes, per channel the count of messages, values that must come
// back exactly, every schema valid JSON Schema and every message valid against its schema, the
// provenance metadata). Here: the log, what orbed-log says about it, and the writer's refusal of a
// stream that ends before its end frame.
//
// The log (t0 = 1.7e15 us): ROBOT_STATE at t0, +10, +40 and +50 ms (the +40 one has 5 joints: a
// message for its JSON channel, refused for /tf), IIWA_STATUS x2 (one with a NaN torque and one
// with exact doubles) plus one with a count of 2^31 - 1 and an hmd_pose_t (another type) on it;
// HMD_POSE; HMD_CAMERA with a real JPEG (OpenCV's encoder) and a GRAY8 frame (not shown on
// /hmd/camera); REFLECTIVE_VIEW; REGISTRATION (valid, request id 2^53 + 1, a session id that is not
// UTF-8); GUIDANCE; COLLISION_STATUS with min_distance_m = +inf; RAW bytes of no known type.
// With the defaults (30 Hz /tf, /scene with the first /tf and when the virtual robot appears): /tf
// at t0 and +50 ms, /scene at t0 and +50 ms (the registration came at +20 ms).
#include "procs/logger/mcap_export.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <orbed/all_types.hpp>

#include "procs/logger/event_log_writer.h"
#include "procs/logger/log_tool.h"

namespace orbed::logger {
namespace {

using json = nlohmann::json;

constexpr int64_t kT0 = 1'700'000'000'000'000;

template <class Msg>
std::vector<uint8_t> Encode(const Msg& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

orbed::pose_t Pose(double x, double y, double z, double w, double qx, double qy, double qz) {
  orbed::pose_t p{};
  p.position_m[0] = x, p.position_m[1] = y, p.position_m[2] = z;
  const double n = std::sqrt(w * w + qx * qx + qy * qy + qz * qz);
  p.quaternion_wxyz[0] = w / n, p.quaternion_wxyz[1] = qx / n, p.quaternion_wxyz[2] = qy / n;
  p.quaternion_wxyz[3] = qz / n;
  return p;
}

json PoseJson(const orbed::pose_t& p) {
  return {{"position_m", std::vector<double>(p.position_m, p.position_m + 3)},
          {"quaternion_wxyz", std::vector<double>(p.quaternion_wxyz, p.quaternion_wxyz + 4)}};
}

orbed::robot_state_t RobotState(int64_t utime, int joints) {
  orbed::robot_state_t s{};
  s.utime = utime;
  s.robot_name = "iiwa";
  s.X_WR = Pose(0.25, -0.5, 0.75, 1, 0, 0, 0.25);
  s.X_RF = s.X_RT = Pose(0, 0, 1.266, 1, 0, 0, 0);
  s.num_joints = joints;
  for (int i = 0; i < joints; ++i) s.joint_position.push_back(0.1 * (i + 1));
  s.joint_limit_hit.assign(joints, 0);
  return s;
}

orbed::iiwa_status_t IiwaStatus(int64_t utime, const std::vector<double>& q) {
  orbed::iiwa_status_t s{};
  s.utime = utime;
  s.num_joints = static_cast<int32_t>(q.size());
  s.joint_position_measured = q;
  s.joint_velocity_estimated = s.joint_position_commanded = s.joint_position_ipo = q;
  s.joint_torque_measured = s.joint_torque_commanded = s.joint_torque_external = q;
  return s;
}

orbed::image_t Jpeg(int64_t utime, const std::vector<uint8_t>& jpeg) {
  orbed::image_t img{};
  img.utime = utime;
  img.width = 16;
  img.height = 8;
  img.pixel_format = orbed::image_t::FORMAT_JPEG;
  img.fx_px = img.fy_px = 20;
  img.cx_px = 8;
  img.cy_px = 4;
  img.X_WC = Pose(1, 2, 1.5, 0.5, 0.5, -0.5, 0.5);
  img.num_bytes = static_cast<int32_t>(jpeg.size());
  img.data = jpeg;
  return img;
}

std::string Read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs a shell command; its exit code and, appended to *output, what it printed (stdout + stderr).
int Shell(const std::string& command, std::string* output) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe)) *output += buffer;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(McapExport, ReadBackByMcapCoreIndexedReader) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "mcap_export_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string log = (dir / "orbed-test.lcmlog").string(), mcap = (dir / "run.mcap").string();
  json expect;

  // A real JPEG of a gradient.
  cv::Mat picture(8, 16, CV_8UC3);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 16; ++c) picture.at<cv::Vec3b>(r, c) = cv::Vec3b(16 * c, 32 * r, 200);
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", picture, jpeg));
  const std::string jpeg_path = (dir / "frame.jpg").string();
  std::ofstream(jpeg_path, std::ios::binary)
      .write(reinterpret_cast<const char*>(jpeg.data()), static_cast<std::streamsize>(jpeg.size()));

  {
    EventLogWriter w(log);
    const auto write = [&w](int64_t t_us, const char* channel, const std::vector<uint8_t>& bytes) {
      ASSERT_GT(w.Write(t_us, channel, bytes.data(), bytes.size()), 0u);
    };
    write(kT0, "ROBOT_STATE", Encode(RobotState(kT0, 7)));
    const std::vector<double> q1 = {0.1, 0.2, 0.30000000000000004, -1.5, 2.0943951023931957, 1e-300, -0.0};
    const std::vector<double> q2 = {0.5, -0.25, 1.0 / 3.0, 0, 0, 0, 0.7};
    orbed::iiwa_status_t with_nan = IiwaStatus(kT0 + 2000, q1);
    with_nan.joint_torque_external[3] = std::numeric_limits<double>::quiet_NaN();
    write(kT0 + 2000, "IIWA_STATUS", Encode(with_nan));
    write(kT0 + 4000, "IIWA_STATUS", Encode(IiwaStatus(kT0 + 4000, q2)));
    std::vector<uint8_t> hostile = Encode(IiwaStatus(kT0 + 5000, q2));
    hostile[16] = 0x7f, hostile[17] = 0xff, hostile[18] = 0xff, hostile[19] = 0xff;  // num_joints
    write(kT0 + 5000, "IIWA_STATUS", hostile);
    orbed::hmd_pose_t pose{};
    pose.utime = kT0 + 6000;
    pose.seq = 3;
    pose.hmd_name = "hmd";
    pose.X_WH = Pose(0.1, 1.2, 1.7, 0.9, 0.1, 0.2, 0.3);
    pose.X_WC = Pose(0.15, 1.2, 1.65, 0.9, 0.1, 0.2, 0.3);
    write(kT0 + 6000, "HMD_POSE", Encode(pose));
    write(kT0 + 7000, "IIWA_STATUS", Encode(pose));  // another type on the channel
    write(kT0 + 8000, "HMD_CAMERA", Encode(Jpeg(kT0 + 7500, jpeg)));
    orbed::image_t gray = Jpeg(kT0 + 8500, {1, 2, 3, 4});
    gray.pixel_format = orbed::image_t::FORMAT_GRAY8;
    write(kT0 + 9000, "HMD_CAMERA", Encode(gray));
    write(kT0 + 10000, "ROBOT_STATE", Encode(RobotState(kT0 + 10000, 7)));
    orbed::reflective_view_t view{};
    view.utime = kT0 + 11000;
    view.display_id = 2;
    view.image = Jpeg(kT0 + 10500, jpeg);
    view.X_WM = view.X_WV = Pose(0, 0, 0, 1, 0, 0, 0);
    for (int i = 0; i < 3; ++i) view.K_m[i][i] = i + 1.5;
    write(kT0 + 11000, "REFLECTIVE_VIEW", Encode(view));
    orbed::registration_t reg{};
    reg.utime = kT0 + 20000;
    reg.session_id = std::string("s\xff", 2) + "1";
    reg.valid = true;
    reg.X_WV_mean = Pose(0.26, -0.49, 0.75, 1, 0, 0, 0.24);
    reg.num_used = 3;
    reg.request_id = (int64_t{1} << 53) + 1;
    write(kT0 + 20000, "REGISTRATION", Encode(reg));
    orbed::guidance_t g{};
    g.utime = kT0 + 30000;
    g.mode = orbed::guidance_t::MODE_AR;
    g.num_joints = 7;
    g.target_position = {0.1, 0.2, 0.3, -0.4, 0.5, 0.6, 0.7};
    g.current_position = {0.1, 0.2, 0.3, -0.4, 0.5, 0.6, 0.75};
    g.error_deg = {0, 0, 0, 0, 0, 0, 2.8647889756541161};
    g.joint_kind.assign(7, int8_t{orbed::guidance_t::JOINT_TWIST});
    g.next_joint = 6;
    write(kT0 + 30000, "GUIDANCE", Encode(g));
    orbed::collision_status_t collision{};
    collision.utime = kT0 + 35000;
    collision.min_distance_m = std::numeric_limits<double>::infinity();
    write(kT0 + 35000, "COLLISION_STATUS", Encode(collision));
    write(kT0 + 40000, "ROBOT_STATE", Encode(RobotState(kT0 + 40000, 5)));
    write(kT0 + 50000, "ROBOT_STATE", Encode(RobotState(kT0 + 50000, 7)));
    write(kT0 + 60000, "RAW", {1, 2, 3, 4, 5, 6, 7, 8, 9});
    w.Close();
    expect["iiwa_positions"] = {q1, q2};
    expect["X_WH"] = PoseJson(pose.X_WH);
    expect["X_WR"] = PoseJson(RobotState(0, 7).X_WR);
    expect["X_WV"] = PoseJson(reg.X_WV_mean);
  }
  // The run's scene, named by its provenance record (as scripts/orbed records launch arguments):
  // /scene draws it, not the shipped OR.
  const std::string scene_path = (dir / "run_scene.yaml").string();
  std::ofstream(scene_path)
      << "name: run_scene\nrobot:\n  base_pose: {position_m: [0.25, -0.55, 0.75], rpy_deg: [0, "
         "0, 90]}\n  tool_length_m: 0.25\ntrocar:\n  position_m: [0.1, 0.0, 1.0]\n  "
         "insertion_direction: [0.0, 0.0, -1.0]\nobjects:\n  - name: only_in_this_run\n    shape: box\n"
         "    size_m: [1.0, 1.0, 0.5]\n    pose: {position_m: [0.0, 0.0, 0.25]}\n";
  const json provenance = {{"format", "orbed.provenance/1"},
                           {"commit", "0123abc"},
                           {"command", {"scripts/orbed", "run"}},
                           {"started_utc", "2026-12-05T03:00:00Z"},
                           {"arguments", {{"scene", scene_path}}}};
  std::ofstream(dir / "provenance.json") << provenance.dump(2);

  std::ostringstream out, err;
  const char* argv[] = {"orbed-log", "export", log.c_str(), mcap.c_str(), "--mcap"};
  ASSERT_EQ(RunLogTool(5, argv, out, err), 0) << err.str();
  const std::string said = out.str();
  EXPECT_NE(said.find("refused 1: count"), std::string::npos) << said;
  EXPECT_NE(said.find("refused 1: another type (hmd_pose_t)"), std::string::npos) << said;
  EXPECT_NE(said.find("refused 1: not on /tf (field)"), std::string::npos) << said;
  EXPECT_NE(said.find("refused 1: not on /hmd/camera (image)"), std::string::npos) << said;
  EXPECT_NE(said.find("refused 1: unknown fingerprint (not exported)"), std::string::npos) << said;
  EXPECT_NE(said.find("provenance: "), std::string::npos) << said;

  // Per channel: the events that decode as the channel's type (what orbed-log info counts, less
  // the refusals above); per Foxglove topic: what the bridge would have sent.
  expect["counts"] = {{"ROBOT_STATE", 4},   {"IIWA_STATUS", 2},      {"HMD_POSE", 1},
                      {"HMD_CAMERA", 2},    {"REFLECTIVE_VIEW", 1},  {"REGISTRATION", 1},
                      {"GUIDANCE", 1},      {"COLLISION_STATUS", 1}, {"/tf", 2},
                      {"/scene", 2},        {"/hmd/camera", 1},      {"/reflective", 1},
                      {"/registration", 1}, {"/guidance", 1}};
  expect["nulls"] = {{{"topic", "IIWA_STATUS"}, {"sequence", 0}, {"path", "/joint_torque_external/3"}},
                     {{"topic", "COLLISION_STATUS"}, {"sequence", 0}, {"path", "/min_distance_m"}}};
  expect["registration_request_id"] = "9007199254740993";
  expect["X_WH_on_second_tf"] = true;
  expect["provenance"] = provenance;
  expect["scene_object"] = "only_in_this_run";
  expect["jpeg_path"] = jpeg_path;
  expect["log_times_ns"] = {{"/hmd/camera", std::to_string(kT0 + 8000) + "000"},
                            {"IIWA_STATUS", std::to_string(kT0 + 2000) + "000"}};
  const std::string expect_path = (dir / "expect.json").string();
  std::ofstream(expect_path) << expect.dump(2);

  std::string output;
  const std::string writer_dir = ORBED_MCAP_WRITER_DIR;
  const int code = Shell("ORBED_MCAP_FILE='" + mcap + "' ORBED_EXPECT_JSON='" + expect_path + "' '" +
                             ORBED_NODE + "' --test '" + writer_dir + "/mcap_export.test.mjs'",
                         &output);
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find("# fail 0"), std::string::npos) << output;
}

TEST(McapExport, WriterLeavesNoFileWithoutTheEndFrame) {
  const std::filesystem::path out = std::filesystem::path(::testing::TempDir()) / "cut_short.mcap";
  std::filesystem::remove(out);
  std::string output;
  const std::string writer_dir = ORBED_MCAP_WRITER_DIR;
  // The input ends before any frame (as when orbed-log stops half-way).
  const int code = Shell("'" + std::string(ORBED_NODE) + "' '" + writer_dir + "/mcap_writer.mjs' '" +
                             out.string() + "' < /dev/null",
                         &output);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("ended before its end frame"), std::string::npos) << output;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".part"));
}

// A log of more channels than kMaxMcapChannels: the channels after it are left out and their
// events counted, before any state is kept for them.
TEST(McapExport, ChannelsBeyondTheLimitAreLeftOutAndCounted) {
  const std::string log = ::testing::TempDir() + "many_channels.lcmlog";
  {
    EventLogWriter w(log);
    const std::vector<uint8_t> status = Encode(IiwaStatus(kT0, {0.5}));
    for (size_t i = 0; i < kMaxMcapChannels + 10; ++i) {
      const std::string channel = "C" + std::to_string(i);
      ASSERT_GT(w.Write(kT0 + static_cast<int64_t>(i), channel, status.data(), status.size()), 0u);
    }
    w.Close();
  }
  struct Counter : RecordSink {
    int channels = 0, messages = 0;
    bool Add(const McapSchemaRecord&) override { return true; }
    bool Add(const McapChannelRecord&) override { return ++channels, true; }
    bool Add(const McapMessageRecord&) override { return ++messages, true; }
    bool Add(const McapMetadataRecord&) override { return true; }
  } sink;
  const MappedLog mapped(log);
  const McapExportResult result = WriteMcapRecords(mapped, McapExportOptions{}, &sink);
  ASSERT_TRUE(result.ok()) << result.error;
  EXPECT_EQ(result.channels.size(), kMaxMcapChannels);
  EXPECT_EQ(result.events_on_channels_left_out, 10);
  EXPECT_EQ(sink.channels, static_cast<int>(kMaxMcapChannels));
  EXPECT_EQ(sink.messages, static_cast<int>(kMaxMcapChannels));
}

TEST(McapExport, MissingLogAndBadArguments) {
  std::ostringstream out, err;
  const char* both[] = {"orbed-log", "export", "x.lcmlog", "y", "--mcap", "--csv"};
  EXPECT_EQ(RunLogTool(6, both, out, err), 2);
}

}  // namespace
}  // namespace orbed::logger
