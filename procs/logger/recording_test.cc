// orbed-logger's core without a bus: the file a new or continued recording goes to, the manifest's
// static fields and hashes, the queue's bounds, the part's counts and the manifest made from them,
// and what a recording ended by a write error says — sizes worked out by hand from the LCM event
// header (28 bytes + channel + payload).
#include "procs/logger/recording.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "procs/logger/event_log_writer.h"

namespace orbed::logger {
namespace {

namespace fs = std::filesystem;

constexpr int64_t kStart = 1'704'164'645'000'000;  // 2024-01-02T03:04:05Z [us]

fs::path EmptyDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("orbed_recording_test_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void WriteEvents(const fs::path& path, int events) {
  EventLogWriter writer(path.string());
  for (int i = 0; i < events; ++i)
    writer.Write(1000 + i, "ABC", reinterpret_cast<const uint8_t*>("12345"), 5);
  ASSERT_TRUE(writer.Close());
}

TEST(Recording, ANewRecordingIsNamedByItsStartAndNeverOverwrites) {
  const fs::path dir = EmptyDir("new");
  std::ofstream(dir / "hashed.txt") << "abc";
  LoggerOptions options;
  options.log_dir = dir.string();
  options.channels = "IIWA_.*";
  options.command_line = "orbed-logger --channels IIWA_.*";
  options.hash_files = {(dir / "hashed.txt").string(), (dir / "missing.txt").string()};
  RecordingStart start = StartRecording(options, "memq://", kStart);
  EXPECT_EQ(start.log_path, (dir / "orbed-20240102T030405Z.lcmlog").string());
  EXPECT_EQ(start.continuing, "");
  EXPECT_EQ(ManifestPath(options), (dir / "manifest.json").string());
  const Manifest& m = start.manifest;
  EXPECT_EQ(m.start_utime, kStart);
  EXPECT_FALSE(m.complete);
  ASSERT_EQ(m.parts.size(), 1u);
  EXPECT_EQ(m.parts[0].file, "orbed-20240102T030405Z.lcmlog");
  EXPECT_EQ(m.parts[0].start_utime, kStart);
  EXPECT_EQ(m.lcm_url, "memq://");
  EXPECT_EQ(m.channels_regex, "IIWA_.*");
  EXPECT_EQ(m.command_line, "orbed-logger --channels IIWA_.*");
  ASSERT_EQ(m.files.size(), 2u);
  // SHA-256("abc"), FIPS 180-2's first example.
  EXPECT_EQ(m.files[0].sha256, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(m.files[1].sha256, "");
  EXPECT_NE(m.files[1].error, "");
  // The name is taken (a logger started within the same second): the next free suffix.
  std::ofstream(start.log_path) << "";
  EXPECT_EQ(StartRecording(options, "memq://", kStart).log_path,
            (dir / "orbed-20240102T030405Z-1.lcmlog").string());
  // --file wins, and puts the manifest beside it.
  options.file = (dir / "sub" / "run.lcmlog").string();
  EXPECT_EQ(StartRecording(options, "memq://", kStart).log_path, options.file);
  EXPECT_EQ(ManifestPath(options), (dir / "sub" / "manifest.json").string());
}

TEST(Recording, AnUnfinishedRecordingContinuesInTheNextFreePartRecounted) {
  const fs::path dir = EmptyDir("continue");
  WriteEvents(dir / "orbed-X.lcmlog", 2);
  Manifest died;
  died.start_utime = 900;
  ManifestPart first;
  first.file = "orbed-X.lcmlog";
  first.start_utime = 900;
  first.stop_utime = 950;  // as the manifest said a while before the logger died
  first.drops = 3;
  died.parts.push_back(first);
  std::string error;
  ASSERT_TRUE(WriteManifestFile((dir / "manifest.json").string(), died, &error)) << error;
  std::ofstream(dir / "orbed-X.part2.lcmlog") << "";  // taken (say, by a logger that failed to start)
  LoggerOptions options;
  options.log_dir = dir.string();
  const RecordingStart start = StartRecording(options, "memq://", kStart);
  EXPECT_EQ(start.log_path, (dir / "orbed-X.part3.lcmlog").string());
  EXPECT_EQ(
      start.continuing,
      "continuing the unfinished recording orbed-X.lcmlog in part 3: its part orbed-X.lcmlog holds 2 events");
  ASSERT_EQ(start.manifest.parts.size(), 2u);
  const ManifestPart& recounted = start.manifest.parts[0];
  EXPECT_EQ(recounted.events, 2);
  EXPECT_EQ(recounted.bytes, 2 * (28 + 3 + 5));
  EXPECT_EQ(recounted.drops, 3);
  EXPECT_EQ(recounted.damaged_bytes, 0);
  EXPECT_EQ(recounted.stop_utime, 1001);
  EXPECT_EQ(recounted.channels.at("ABC").events, 2);
  EXPECT_EQ(recounted.channels.at("ABC").bytes, 10);
  EXPECT_EQ(start.manifest.start_utime, 900);
  EXPECT_EQ(start.manifest.parts[1].file, "orbed-X.part3.lcmlog");
  EXPECT_EQ(start.manifest.parts[1].start_utime, kStart);
  // A complete recording is not continued.
  died.complete = died.parts[0].complete = true;
  died.stop_utime = 950;
  ASSERT_TRUE(WriteManifestFile((dir / "manifest.json").string(), died, &error)) << error;
  EXPECT_EQ(StartRecording(options, "memq://", kStart).continuing, "");
}

TEST(Recording, TheQueueDropsWhatDoesNotFitAndLogsTheFirstAndEveryThousandth) {
  LoggerOptions options;
  options.queue_capacity_events = 2;
  options.queue_capacity_bytes = 10;
  EXPECT_TRUE(QueueFits(options, 1, 4, 6));
  EXPECT_FALSE(QueueFits(options, 1, 4, 7));
  EXPECT_FALSE(QueueFits(options, 2, 0, 1));
  EXPECT_TRUE(LogDrop(1));
  EXPECT_FALSE(LogDrop(2));
  EXPECT_TRUE(LogDrop(2000));
}

TEST(Recording, ThePartsCountsMakeTheManifest) {
  PartCounts counts;
  counts.Written("A", 200, 5, 28 + 1 + 5);
  counts.Written("A", 100, 3, 28 + 1 + 3);
  counts.Written("BB", 150, 1, 28 + 2 + 1);
  EXPECT_EQ(counts.events_written, 3);
  EXPECT_EQ(counts.bytes_written, 34 + 32 + 31);
  EXPECT_EQ(counts.channels.at("A").events, 2);
  EXPECT_EQ(counts.channels.at("A").bytes, 8);
  EXPECT_EQ(counts.channels.at("A").first_utime, 200);  // the first written, in the order received
  EXPECT_EQ(counts.channels.at("A").last_utime, 100);
  Manifest recording;
  recording.parts.resize(2);
  recording.parts[1].file = "this.lcmlog";
  Manifest m = ManifestNow(recording, counts, 4, false, 0);
  EXPECT_FALSE(m.complete);
  EXPECT_FALSE(m.stop_utime);
  EXPECT_EQ(m.parts[1].events, 3);
  EXPECT_EQ(m.parts[1].bytes, 97);
  EXPECT_EQ(m.parts[1].drops, 4);
  EXPECT_EQ(m.parts[1].channels.size(), 2u);
  EXPECT_EQ(m.parts[0].events, 0);  // earlier parts as they were
  m = ManifestNow(recording, counts, 4, true, 777);
  EXPECT_TRUE(m.complete && m.parts[1].complete);
  EXPECT_EQ(m.stop_utime, 777);
  EXPECT_EQ(m.parts[1].stop_utime, 777);
}

TEST(Recording, AFailedRecordingSaysWhatItsFileHolds) {
  const fs::path dir = EmptyDir("failed");
  const fs::path log = dir / "run.lcmlog";
  WriteEvents(log, 1);
  Manifest manifest;
  manifest.parts.resize(1);
  manifest.parts[0].file = "run.lcmlog";
  std::string line;
  // 3 events handed to the writer, 1 in the file: 2 drops.
  Manifest failed = FailedRecording(manifest, "cannot write run.lcmlog: No space left on device (ENOSPC)",
                                    true, log.string(), 3, &line);
  EXPECT_EQ(line, "cannot write run.lcmlog: No space left on device (ENOSPC) after 36 bytes, 1 events");
  EXPECT_EQ(failed.parts[0].error, line);
  EXPECT_EQ(failed.parts[0].events, 1);
  EXPECT_EQ(failed.parts[0].drops, 2);
  failed = FailedRecording(manifest, "cannot write manifest.json", false, log.string(), 1, &line);
  EXPECT_EQ(line, "cannot write manifest.json; the log " + log.string() + " holds 36 bytes, 1 events");
  failed = FailedRecording(manifest, "x", true, (dir / "gone.lcmlog").string(), 0, &line);
  EXPECT_EQ(line.rfind("x; the log cannot be read back: ", 0), 0u) << line;
}

}  // namespace
}  // namespace orbed::logger
