// Unit tests of orbed-logger's engine on memq://. The oracle for the file format is LCM's own
// log reader (lcm::LogFile), not our writer.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/iiwa_status_t.hpp>

#include "base/sha256.h"
#include "base/test_command.h"
#include "procs/logger/event_log_writer.h"
#include "procs/logger/logger.h"
#include "procs/logger/logger_cli.h"

namespace orbed::logger {
namespace {

namespace fs = std::filesystem;

// A fresh temporary folder, removed at exit when every test passed.
fs::path TempDir(const std::string& name) {
  static std::vector<fs::path> dirs;
  fs::path dir = fs::temp_directory_path() / ("orbed_logger_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  if (dirs.empty()) {
    std::atexit([] {
      if (!::testing::UnitTest::GetInstance()->Passed()) return;
      std::error_code ec;
      for (const fs::path& d : dirs) fs::remove_all(d, ec);
    });
  }
  dirs.push_back(dir);
  return dir;
}

struct ReadEvent {
  int64_t number, timestamp;
  std::string channel, data;
};

std::vector<ReadEvent> ReadWithLcm(const std::string& path) {
  lcm::LogFile log(path, "r");
  EXPECT_TRUE(log.good());
  std::vector<ReadEvent> events;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    events.push_back({event->eventnum, event->timestamp, event->channel,
                      std::string(static_cast<const char*>(event->data), event->datalen)});
  }
  return events;
}

TEST(EventLogWriter, LcmReadsBackWhatWasWritten) {
  const fs::path dir = TempDir("format");
  const std::string path = (dir / "a.lcmlog").string();
  {
    EventLogWriter writer(path);
    ASSERT_TRUE(writer.ok()) << writer.error();
    EXPECT_EQ(writer.Write(1000, "A", reinterpret_cast<const uint8_t*>("xyz"), 3),
              EventLogWriter::kHeaderBytes + 1 + 3);
    writer.Write(2000, "CHANNEL_B", reinterpret_cast<const uint8_t*>(""), 0);
    std::string big(300000, '\x7f');
    writer.Write(3000, "IMG", reinterpret_cast<const uint8_t*>(big.data()), big.size());
  }
  const std::vector<ReadEvent> events = ReadWithLcm(path);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].number, 0);
  EXPECT_EQ(events[0].timestamp, 1000);
  EXPECT_EQ(events[0].channel, "A");
  EXPECT_EQ(events[0].data, "xyz");
  EXPECT_EQ(events[1].channel, "CHANNEL_B");
  EXPECT_EQ(events[1].data, "");
  EXPECT_EQ(events[2].number, 2);
  EXPECT_EQ(events[2].data.size(), 300000u);
  // Header + channel + payload, summed by hand: (28+1+3) + (28+9+0) + (28+3+300000).
  EXPECT_EQ(fs::file_size(path), 32u + 37u + 300031u);
}

TEST(EventLogWriter, LogCutMidEventIsReadUpToTheLastWholeEvent) {
  const fs::path dir = TempDir("cut");
  const std::string path = (dir / "cut.lcmlog").string();
  {
    EventLogWriter writer(path);
    for (int i = 0; i < 5; ++i) {
      const std::string payload(100, static_cast<char>('a' + i));
      writer.Write(i, "CH", reinterpret_cast<const uint8_t*>(payload.data()), payload.size());
    }
  }
  // Each event is 28 + 2 + 100 = 130 bytes; cut the 5th in the middle of its payload, and
  // separately in the middle of its header.
  for (uintmax_t size : {4u * 130u + 70u, 4u * 130u + 10u}) {
    fs::resize_file(path, size);
    const std::vector<ReadEvent> events = ReadWithLcm(path);
    ASSERT_EQ(events.size(), 4u) << "cut at " << size;
    EXPECT_EQ(events[3].data, std::string(100, 'd'));
  }
}

TEST(EventLogWriter, UnwritablePathIsReported) {
  EventLogWriter writer("/nonexistent-dir/x/y.lcmlog");
  EXPECT_FALSE(writer.ok());
  EXPECT_NE(writer.error().find("/nonexistent-dir/x/y.lcmlog"), std::string::npos);
}

// The logger on memq:// hears what is published on its own LCM instance.
TEST(Logger, RecordsEveryChannelWritesManifestAndCountsDrops) {
  const fs::path dir = TempDir("logger");
  const fs::path hashed = dir / "model.urdf";
  { std::ofstream(hashed) << "<robot name='x'/>"; }
  CommonFlags flags("orbed-logger");
  flags.lcm_url = "memq://";
  flags.duration_s = 1.2;
  LoggerOptions options;
  options.log_dir = dir.string();
  options.hash_files = {hashed.string(), (dir / "missing.yaml").string()};
  options.queue_capacity_bytes = 10000;  // a bigger message cannot fit: dropped and counted
  Logger logger(flags, options);

  iiwa_status_t status{};
  status.num_joints = 7;
  for (auto* v : {&status.joint_position_measured, &status.joint_velocity_estimated,
                  &status.joint_position_commanded, &status.joint_position_ipo, &status.joint_torque_measured,
                  &status.joint_torque_commanded, &status.joint_torque_external}) {
    v->assign(7, 0.25);
  }
  for (int i = 0; i < 10; ++i) {
    status.utime = i;
    logger.process().lcm().publish("IIWA_STATUS", &status);
  }
  logger.process().lcm().publish("LCM_SELF_TEST", "lcm self test", 13);  // LCM's probe: skipped
  const std::string too_big(20000, 'x');
  logger.process().lcm().publish("HMD_CAMERA", too_big.data(), too_big.size());
  EXPECT_EQ(logger.Run(), 0);

  const std::vector<ReadEvent> events = ReadWithLcm(logger.log_path());
  int iiwa = 0, logger_status = 0, heartbeats = 0;
  for (const ReadEvent& e : events) {
    if (e.channel == "IIWA_STATUS") {
      iiwa_status_t decoded;
      ASSERT_EQ(decoded.decode(e.data.data(), 0, e.data.size()), static_cast<int>(e.data.size()));
      EXPECT_EQ(decoded.utime, iiwa);  // in publication order
      ++iiwa;
    }
    logger_status += e.channel == "LOGGER_STATUS";
    heartbeats += e.channel == "PROCESS_STATUS";
    EXPECT_NE(e.channel, "HMD_CAMERA");
    EXPECT_NE(e.channel, "LCM_SELF_TEST");
  }
  EXPECT_EQ(iiwa, 10);
  EXPECT_GE(logger_status, 1);
  EXPECT_GE(heartbeats, 2);
  const orbed::logger_status_t final_status = logger.MakeStatus();
  EXPECT_EQ(final_status.drops, 1);
  EXPECT_EQ(final_status.events_written, static_cast<int64_t>(events.size()));
  EXPECT_EQ(final_status.bytes_written, static_cast<int64_t>(fs::file_size(logger.log_path())));

  std::ifstream manifest_in(logger.manifest_path());
  std::stringstream manifest;
  manifest << manifest_in.rdbuf();
  const std::string text = manifest.str();
  EXPECT_NE(text.find("\"complete\": true"), std::string::npos);
  EXPECT_NE(text.find("\"drops\": 1"), std::string::npos);
  EXPECT_NE(text.find("\"IIWA_STATUS\""), std::string::npos);
  EXPECT_NE(text.find("\"events\": 10"), std::string::npos);
  EXPECT_NE(text.find(Sha256Hex("<robot name='x'/>")), std::string::npos);
  EXPECT_NE(text.find("cannot read"), std::string::npos);
  EXPECT_NE(text.find("\"lcm\": \"1.3.1\""), std::string::npos);
}

// A full disk (/dev/full: every write fails with ENOSPC) stops the logger with kExitCannotWrite,
// which orbed-launch does not respawn, and its manifest part says why.
TEST(Logger, WriteErrorsFailTheLogger) {
  CommonFlags flags("orbed-logger");
  flags.lcm_url = "memq://";
  flags.duration_s = 2.0;
  LoggerOptions options;
  options.file = "/dev/full";
  options.manifest = (TempDir("full") / "manifest.json").string();
  options.flush_interval_s = 0.05;
  Logger logger(flags, options);
  const std::string payload(100000, 'x');
  for (int i = 0; i < 20; ++i) logger.process().lcm().publish("BLOB", payload.data(), payload.size());
  EXPECT_EQ(logger.Run(), kExitCannotWrite);
  EXPECT_EQ(logger.process().MakeStatus().state, +orbed::process_status_t::STATE_FAILED);
  const Manifest manifest = ReadManifestFile(options.manifest);
  EXPECT_FALSE(manifest.complete);
  EXPECT_NE(manifest.parts.back().error.find("cannot write /dev/full: No space left on device (ENOSPC)"),
            std::string::npos)
      << manifest.parts.back().error;
}

TEST(Logger, MalformedChannelRegexThrowsBeforeCreatingAFile) {
  const fs::path dir = TempDir("bad_regex");
  CommonFlags flags("orbed-logger");
  flags.lcm_url = "memq://";
  LoggerOptions options;
  options.log_dir = (dir / "logs").string();
  options.channels = "IIWA_(";
  EXPECT_THROW(Logger(flags, options), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "logs"));
}

TEST(Logger, ChannelRegexSelects) {
  const fs::path dir = TempDir("regex");
  CommonFlags flags("orbed-logger");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.3;
  LoggerOptions options;
  options.file = (dir / "only_hmd.lcmlog").string();
  options.channels = "HMD_.*";
  Logger logger(flags, options);
  for (const char* channel : {"HMD_POSE", "IIWA_STATUS", "HMD_CAMERA", "XHMD_POSE"}) {
    logger.process().lcm().publish(channel, "abc", 3);
  }
  EXPECT_EQ(logger.Run(), 0);
  const std::vector<ReadEvent> events = ReadWithLcm(options.file);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].channel, "HMD_POSE");
  EXPECT_EQ(events[1].channel, "HMD_CAMERA");
}

// The command line, in-process.
TEST(LoggerCli, HelpGoesToOutAndExitsZero) {
  const test::CommandRun r = test::RunCommand(RunLogger, "orbed-logger", {"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--flush-interval-s"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(LoggerCli, RefusesAnUnknownFlagAndABadValue) {
  test::CommandRun r = test::RunCommand(RunLogger, "orbed-logger", {"--no-such-flag"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--no-such-flag"), std::string::npos) << r.err;
  r = test::RunCommand(RunLogger, "orbed-logger", {"--flush-interval-s", "-1"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--flush-interval-s"), std::string::npos) << r.err;
  // Found when the logger starts, not by the parser: exit 2, and no file is created.
  const fs::path dir = TempDir("cli_regex");
  r = test::RunCommand(RunLogger, "orbed-logger",
                       {"--lcm-url", "memq://", "--file", (dir / "x.lcmlog").string(), "--channels", "("});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("orbed-logger: "), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "x.lcmlog"));
}

TEST(LoggerCli, RecordsUntilTheDurationAndWritesTheManifest) {
  const fs::path dir = TempDir("cli_run");
  const test::CommandRun r = test::RunCommand(
      RunLogger, "orbed-logger",
      {"--lcm-url", "memq://", "--duration-s", "0.2", "--file", (dir / "run.lcmlog").string()});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "run.lcmlog"));
  std::ifstream manifest(dir / "manifest.json");
  std::stringstream text;
  text << manifest.rdbuf();
  // The manifest records the command line as given.
  EXPECT_NE(text.str().find("orbed-logger --lcm-url memq:// --duration-s 0.2"), std::string::npos)
      << text.str();
}

}  // namespace
}  // namespace orbed::logger
