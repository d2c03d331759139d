// orbed-log export --csv on a log whose messages are known by construction, read back with Python's
// csv module (an independent reader of RFC 4180):
//   - header: field paths with units from the .lcm files, "log_utime (us)" first;
//   - values: integers, shortest round-trip doubles, nan, booleans 1/0, a quoted string with a comma
//     and a quote, byte arrays as their length;
//   - arrays that change length: the longest message's columns, in field order, empty cells for the
//     shorter messages;
//   - hostile input: a count of 2^31 - 1, another type's message on the channel, bytes of no known
//     type; each refused, counted by reason, and no row;
//   - file names from channel names; --channels and the time range.
#include "procs/logger/csv_export.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/guidance_t.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/image_t.hpp>

#include "base/test_command.h"
#include "procs/logger/event_log_writer.h"
#include "procs/logger/log_tool.h"

namespace orbed::logger {
namespace {

template <class Msg>
std::vector<uint8_t> Encode(const Msg& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

orbed::guidance_t Guidance(int64_t utime, std::vector<double> target) {
  orbed::guidance_t g{};
  g.utime = utime;
  g.mode = orbed::guidance_t::MODE_FIXED_DISPLAY;
  g.num_joints = static_cast<int32_t>(target.size());
  g.target_position = target;
  g.current_position.assign(target.size(), 0.5);
  g.error_deg.assign(target.size(), -1.25);
  g.joint_kind.assign(target.size(), int8_t{orbed::guidance_t::JOINT_REVOLVE});
  g.next_joint = -1;
  g.done = true;
  return g;
}

// The rows of a CSV file as Python's csv module reads them (cells joined by '|', one row per line).
std::vector<std::string> ReadWithPython(const std::string& path) {
  const std::string command =
      "python3 -c \"import csv,sys; [print('|'.join(r)) for r in csv.reader(open(sys.argv[1], "
      "newline=''))]\" '" +
      path + "'";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  std::vector<std::string> rows;
  if (!pipe) return rows;
  std::array<char, 8192> buffer;
  std::string text;
  while (fgets(buffer.data(), buffer.size(), pipe.get())) text += buffer.data();
  size_t start = 0;
  for (size_t end; (end = text.find('\n', start)) != std::string::npos; start = end + 1)
    rows.push_back(text.substr(start, end - start));
  return rows;
}

// GUIDANCE: 2 joints at t = 0, a hostile count, an HMD pose, 3 joints at 0.2 s, 2 at 0.3 s.
// "HEAD/SET 1": one hmd_pose_t. RAW: 4 bytes of nothing known. IMAGE: an image_t with 5 data bytes.
std::string WriteKnownLog(const std::string& name) {
  const std::string path = ::testing::TempDir() + name;
  EventLogWriter w(path);
  const auto write = [&w](int64_t t_us, const char* channel, const std::vector<uint8_t>& bytes) {
    w.Write(t_us, channel, bytes.data(), bytes.size());
  };
  write(1'000'000, "GUIDANCE", Encode(Guidance(11, {0.1, -0.25})));
  std::vector<uint8_t> hostile = Encode(Guidance(12, {0.1, -0.25}));
  // fingerprint 8 | utime 8 | mode 1 | num_joints 4 (big-endian) at byte 17.
  hostile[17] = 0x7f, hostile[18] = 0xff, hostile[19] = 0xff, hostile[20] = 0xff;
  write(1'050'000, "GUIDANCE", hostile);
  orbed::hmd_pose_t pose{};
  pose.utime = 99;
  pose.seq = 7;
  pose.hmd_name = "left, \"front\"";
  pose.X_WH.position_m[0] = 1.5;
  pose.X_WH.position_m[1] = std::nan("");
  pose.X_WH.position_m[2] = 1e-300;
  pose.X_WH.quaternion_wxyz[0] = 1;
  pose.X_WC.quaternion_wxyz[0] = 1;
  pose.tracking_state = orbed::hmd_pose_t::RELOCALIZED;
  write(1'100'000, "GUIDANCE", Encode(pose));
  write(1'150'000, "HEAD/SET 1", Encode(pose));
  write(1'200'000, "GUIDANCE", Encode(Guidance(13, {1, 2, 3})));
  write(1'250'000, "RAW", {1, 2, 3, 4});
  orbed::image_t image{};
  image.utime = 5;
  image.pixel_format = orbed::image_t::FORMAT_JPEG;
  image.X_WC.quaternion_wxyz[0] = 1;
  image.num_bytes = 5;
  image.data = {9, 9, 9, 9, 9};
  write(1'280'000, "IMAGE", Encode(image));
  write(1'300'000, "GUIDANCE", Encode(Guidance(14, {4, 5})));
  w.Close();
  return path;
}

TEST(CsvExport, ColumnsUnitsValuesAndRefusals) {
  const std::string log = WriteKnownLog("export.lcmlog");
  const std::string dir = ::testing::TempDir() + "export_csv";
  const test::CommandRun r = test::RunCommand(RunLogTool, "orbed-log", {"export", log, dir, "--csv"});
  ASSERT_EQ(r.code, 0) << r.err;

  const std::vector<std::string> guidance = ReadWithPython(dir + "/GUIDANCE.csv");
  ASSERT_EQ(guidance.size(), 4u) << r.out;  // header + three rows; the hostile and the pose refused
  EXPECT_EQ(guidance[0],
            "log_utime (us)|utime (us)|mode|num_joints|target_position[0] (rad)|target_position[1] (rad)|"
            "target_position[2] (rad)|current_position[0] (rad)|current_position[1] (rad)|"
            "current_position[2] (rad)|error_deg[0] (deg)|error_deg[1] (deg)|error_deg[2] (deg)|"
            "joint_kind[0]|joint_kind[1]|joint_kind[2]|next_joint|done");
  EXPECT_EQ(guidance[1], "1000000|11|2|2|0.1|-0.25||0.5|0.5||-1.25|-1.25||1|1||-1|1");
  EXPECT_EQ(guidance[2], "1200000|13|2|3|1|2|3|0.5|0.5|0.5|-1.25|-1.25|-1.25|1|1|1|-1|1");
  EXPECT_EQ(guidance[3], "1300000|14|2|2|4|5||0.5|0.5||-1.25|-1.25||1|1||-1|1");

  const std::vector<std::string> pose = ReadWithPython(dir + "/HEAD_SET_1.csv");
  ASSERT_EQ(pose.size(), 2u);
  EXPECT_EQ(pose[0],
            "log_utime (us)|utime (us)|seq|hmd_name|X_WH.position_m[0] (m)|X_WH.position_m[1] (m)|"
            "X_WH.position_m[2] (m)|X_WH.quaternion_wxyz[0]|X_WH.quaternion_wxyz[1]|X_WH.quaternion_wxyz[2]|"
            "X_WH.quaternion_wxyz[3]|X_WC.position_m[0] (m)|X_WC.position_m[1] (m)|X_WC.position_m[2] (m)|"
            "X_WC.quaternion_wxyz[0]|X_WC.quaternion_wxyz[1]|X_WC.quaternion_wxyz[2]|"
            "X_WC.quaternion_wxyz[3]|tracking_state");
  EXPECT_EQ(pose[1], "1150000|99|7|left, \"front\"|1.5|nan|1e-300|1|0|0|0|0|0|0|1|0|0|0|3");

  const std::vector<std::string> images = ReadWithPython(dir + "/IMAGE.csv");
  ASSERT_EQ(images.size(), 2u);
  EXPECT_NE(images[0].find("|num_bytes|data (bytes)"), std::string::npos) << images[0];
  EXPECT_EQ(images[1].substr(images[1].size() - 4), "|5|5") << images[1];

  EXPECT_FALSE(std::ifstream(dir + "/RAW.csv").good());
  EXPECT_NE(r.out.find("RAW: not exported, no orbed or Drake fingerprint (1 events)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  refused 1: count\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  refused 1: another type (hmd_pose_t)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 CSV file(s)"), std::string::npos) << r.out;
}

TEST(CsvExport, ChannelsAndTimeRange) {
  const std::string log = WriteKnownLog("export_range.lcmlog");
  const std::string dir = ::testing::TempDir() + "export_range";
  const test::CommandRun r =
      test::RunCommand(RunLogTool, "orbed-log",
                       {"export", log, dir, "--from-s", "0.15", "--to-s", "0.25", "--channels", "GUID.*"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<std::string> rows = ReadWithPython(dir + "/GUIDANCE.csv");
  ASSERT_EQ(rows.size(), 2u);  // the guidance at 0.2 s only
  EXPECT_EQ(rows[1].substr(0, 11), "1200000|13|");
  EXPECT_FALSE(std::ifstream(dir + "/IMAGE.csv").good());
  EXPECT_NE(r.out.find("1 CSV file(s)"), std::string::npos) << r.out;
}

TEST(CsvExport, FileStems) {
  EXPECT_EQ(CsvFileStem("IIWA_STATUS"), "IIWA_STATUS");
  EXPECT_EQ(CsvFileStem("a/b c"), "a_b_c");
  EXPECT_EQ(CsvFileStem(".."), "_..");
  EXPECT_EQ(CsvFileStem(""), "_");
  EXPECT_EQ(CsvFileStem("caf\xc3\xa9"), "caf__");
}

}  // namespace
}  // namespace orbed::logger
