// manifest.json (manifest.h): what the writer writes the reader reads back; every consistency rule
// refuses a document that breaks it, naming the key; and a logger started on an unfinished
// recording continues it in the next part, leaving the earlier part byte for byte as it was and
// listing what it really holds.
#include "procs/logger/manifest.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "procs/logger/event_log_reader.h"
#include "procs/logger/event_log_writer.h"
#include "procs/logger/logger.h"

namespace orbed::logger {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("orbed_manifest_test_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Two parts: the first from a logger that died, the second stopped cleanly.
Manifest TwoParts() {
  Manifest m;
  m.complete = true;
  m.start_utime = 1'700'000'000'000'000;
  m.stop_utime = m.start_utime + 9'000'000;
  m.command_line = "orbed-logger --log-dir logs";
  m.orbed_version = "0.1.0";
  m.lcm_version = "1.3.1";
  m.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  m.channels_regex = ".*";
  m.files = {{"/a/iiwa7.urdf", std::string(64, 'a'), ""},
             {"/a/missing.yaml", "", "cannot read /a/missing.yaml"}};
  ManifestPart first;
  first.file = "orbed-X.lcmlog";
  first.start_utime = m.start_utime;
  first.stop_utime = m.start_utime + 3'000'000;
  first.channels["IIWA_STATUS"] = {600, 600 * 412, m.start_utime + 10, m.start_utime + 2'990'000};
  first.channels["AB"] = {2, 7, m.start_utime + 20, m.start_utime + 30};
  first.events = 602;
  first.bytes = 600 * (28 + 11) + 600 * 412 + 2 * (28 + 2) + 7;
  first.damaged_bytes = 13;
  first.drops = 1;
  ManifestPart second;
  second.file = "orbed-X.part2.lcmlog";
  second.start_utime = m.start_utime + 4'000'000;
  second.stop_utime = *m.stop_utime;
  second.complete = true;
  second.channels["IIWA_STATUS"] = {1000, 1000 * 412, m.start_utime + 4'000'010, m.start_utime + 8'990'000};
  second.events = 1000;
  second.bytes = 1000 * (28 + 11) + 1000 * 412;
  m.parts = {first, second};
  return m;
}

TEST(Manifest, ReadsBackWhatItWrites) {
  const Manifest m = TwoParts();
  const std::string text = ManifestJson(m);
  const Manifest back = ParseManifest(text, "m.json");
  EXPECT_EQ(ManifestJson(back), text);
  ASSERT_EQ(back.parts.size(), 2u);
  EXPECT_EQ(back.parts[0].damaged_bytes, 13);
  EXPECT_FALSE(back.parts[0].complete);
  EXPECT_EQ(back.events(), 1602);
  EXPECT_EQ(back.drops(), 1);
  const auto channels = back.channels();
  EXPECT_EQ(channels.at("IIWA_STATUS").events, 1600);
  EXPECT_EQ(channels.at("IIWA_STATUS").first_utime, m.start_utime + 10);
  EXPECT_EQ(channels.at("IIWA_STATUS").last_utime, m.start_utime + 8'990'000);
  // What the tools read: the recording's name and totals.
  const nlohmann::json doc = nlohmann::json::parse(text);
  EXPECT_EQ(doc["log_file"], "orbed-X.lcmlog");
  EXPECT_EQ(doc["events_written"], 1602);
  EXPECT_EQ(doc["channels"]["AB"]["events"], 2);
  EXPECT_EQ(doc["start_time_utc"], "2023-11-14T22:13:20Z");
}

// A part whose logger stopped on a write error says why; a part without one has no "error" key.
TEST(Manifest, APartsWriteErrorReadsBack) {
  Manifest m = TwoParts();
  m.complete = false;
  m.stop_utime.reset();
  m.parts[1].complete = false;
  m.parts[1].error =
      "cannot write /d/orbed-X.part2.lcmlog: No space left on device (ENOSPC) after 13 bytes, 0 events";
  const std::string text = ManifestJson(m);
  const Manifest back = ParseManifest(text, "m.json");
  EXPECT_EQ(back.parts[1].error, m.parts[1].error);
  EXPECT_EQ(back.parts[0].error, "");
  EXPECT_EQ(nlohmann::json::parse(text)["parts"][0].count("error"), 0u);
  EXPECT_EQ(ManifestJson(back), text);
}

std::string RefusalOf(const std::function<void(nlohmann::json&)>& damage) {
  nlohmann::json doc = nlohmann::json::parse(ManifestJson(TwoParts()));
  damage(doc);
  try {
    ParseManifest(doc.dump(), "m.json");
  } catch (const JsonReadError& e) {
    return e.what();
  }
  return "";
}

TEST(Manifest, RefusesInconsistentDocumentsNamingTheKey) {
  EXPECT_EQ(RefusalOf([](nlohmann::json&) {}), "");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["parts"][1]["file"] = "../etc/passwd"; }),
            "m.json: parts[1].file: expected a file name of its own (no '/'), got \"../etc/passwd\"");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["parts"][1]["file"] = "orbed-X.lcmlog"; }).substr(0, 22),
            "m.json: parts[1].file:");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["parts"][0]["events"] = 603; }),
            "m.json: parts[0].events: expected the sum of its channels' events, 602");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["parts"][0]["bytes"] = 1; }).substr(0, 25),
            "m.json: parts[0].bytes: e");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["events_written"] = 1; }),
            "m.json: events_written: expected the parts' sum, 1602");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["drops"] = 0; }),
            "m.json: drops: expected the parts' sum, 1");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["channels"]["AB"]["events"] = 3; }),
            "m.json: channels.AB: expected the sum over the parts");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["channels"].erase("AB"); }),
            "m.json: channels: expected the channels of the parts");
  EXPECT_EQ(
      RefusalOf([](nlohmann::json& d) { d["parts"][0]["complete"] = true; }),
      "m.json: parts[0].complete: expected false: only the last part of a complete recording is complete");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["complete"] = false; }),
            "m.json: stop_utime: expected no stop time");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["parts"] = nlohmann::json::array(); }),
            "m.json: parts: expected at least one part");
  EXPECT_EQ(
      RefusalOf([](nlohmann::json& d) { d["parts"][0]["channels"]["AB"]["last_utime"] = 0; }).substr(0, 42),
      "m.json: parts[0].channels.AB.last_utime: e");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["files"][0]["sha256"] = "xyz"; }).substr(0, 31),
            "m.json: files[0].sha256: expect");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["log_file"] = "other.lcmlog"; }),
            "m.json: log_file: expected the first part's file");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["parts"][0]["events"] = -1; }).substr(0, 31),
            "m.json: parts[0].events: expect");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) {
              d["parts"][0]["channels"]["AB"]["events"] = 9223372036854775807;
              d["parts"][0]["events"] = 9223372036854775807;
            }),
            "m.json: parts[0].bytes: expected sums within 64 bits");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d.erase("versions"); }),
            "m.json: versions: expected a value (missing)");
  // Not JSON at all, and too deep.
  EXPECT_THROW(ParseManifest("{\"complete\": tru", "m.json"), JsonReadError);
  EXPECT_THROW(ParseManifest(std::string(100, '[') + std::string(100, ']'), "m.json"), JsonReadError);
}

TEST(Manifest, PartNamesFollowTheFirstPart) {
  EXPECT_EQ(PartFileName("orbed-20240101T000000Z.lcmlog", 2), "orbed-20240101T000000Z.part2.lcmlog");
  EXPECT_EQ(PartFileName("run.log", 12), "run.part12.log");
  EXPECT_EQ(PartFileName("plain", 3), "plain.part3");
  EXPECT_EQ(PartFileName(".hidden", 2), ".hidden.part2");
}

// A logger on memq:// recording into `dir` for `duration_s`, with a few events of its own.
Manifest RecordAndStop(const fs::path& dir, int events) {
  CommonFlags flags("orbed-logger");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.3;
  LoggerOptions options;
  options.log_dir = dir.string();
  Logger logger(flags, options);
  for (int i = 0; i < events; ++i) logger.process().lcm().publish("DATA", "abc", 3);
  EXPECT_EQ(logger.Run(), 0);
  return ReadManifestFile(logger.manifest_path());
}

TEST(Manifest, ALoggerContinuesAnUnfinishedRecordingInTheNextPart) {
  const fs::path dir = FreshDir("continue");
  // What a logger killed mid-run leaves: its part valid up to the last flush plus a torn event, and
  // a manifest written a while before (stale counts, not complete).
  {
    EventLogWriter writer((dir / "orbed-X.lcmlog").string());
    for (int i = 0; i < 5; ++i)
      writer.Write(1000 + i, "IIWA_STATUS", reinterpret_cast<const uint8_t*>("12345"), 5);
    writer.Close();
    std::ofstream(dir / "orbed-X.lcmlog", std::ios::binary | std::ios::app)
        << std::string("\xED\xA1\xDA\x01\0\0", 6);
  }
  Manifest died = TwoParts();
  died.complete = false;
  died.stop_utime.reset();
  died.parts.resize(1);
  died.parts[0].file = "orbed-X.lcmlog";
  died.parts[0].start_utime = died.start_utime = 900;
  std::string error;
  ASSERT_TRUE(WriteManifestFile((dir / "manifest.json").string(), died, &error)) << error;
  const std::string first_part = FileBytes(dir / "orbed-X.lcmlog");

  const Manifest m = RecordAndStop(dir, 4);
  EXPECT_EQ(FileBytes(dir / "orbed-X.lcmlog"), first_part);  // not touched
  EXPECT_TRUE(m.complete);
  EXPECT_EQ(m.start_utime, 900);
  ASSERT_EQ(m.parts.size(), 2u);
  // Part 1 as it really is: 5 whole events, the torn one counted as damage, its end the last event.
  EXPECT_EQ(m.parts[0].file, "orbed-X.lcmlog");
  EXPECT_FALSE(m.parts[0].complete);
  EXPECT_EQ(m.parts[0].events, 5);
  EXPECT_EQ(m.parts[0].bytes, 5 * (28 + 11 + 5));
  EXPECT_EQ(m.parts[0].damaged_bytes, 6);
  EXPECT_EQ(m.parts[0].stop_utime, 1004);
  EXPECT_EQ(m.parts[0].channels.at("IIWA_STATUS").events, 5);
  EXPECT_EQ(m.parts[0].drops, 1);  // as the dead logger last wrote it
  // Part 2: this logger's, whole.
  EXPECT_EQ(m.parts[1].file, "orbed-X.part2.lcmlog");
  EXPECT_TRUE(m.parts[1].complete);
  EXPECT_EQ(m.parts[1].channels.at("DATA").events, 4);
  EXPECT_EQ(m.parts[1].bytes, static_cast<int64_t>(fs::file_size(dir / "orbed-X.part2.lcmlog")));
  EXPECT_EQ(m.events(), 5 + m.parts[1].events);
  const MappedLog part2((dir / "orbed-X.part2.lcmlog").string());
  EventLogScanner scanner = part2.Scanner();
  LogEvent event;
  int64_t scanned = 0;
  while (scanner.Next(&event)) ++scanned;
  EXPECT_EQ(scanned, m.parts[1].events);
  EXPECT_EQ(scanner.damaged_bytes(), 0u);

  // The recording is complete now: the next logger starts a new one.
  const Manifest next = RecordAndStop(dir, 1);
  ASSERT_EQ(next.parts.size(), 1u);
  EXPECT_NE(next.parts[0].file, "orbed-X.lcmlog");
  EXPECT_EQ(next.parts[0].file.find(".part"), std::string::npos);
}

std::string LoggerRefusal(const fs::path& dir) {
  CommonFlags flags("orbed-logger");
  flags.lcm_url = "memq://";
  LoggerOptions options;
  options.log_dir = dir.string();
  try {
    Logger logger(flags, options);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(Manifest, ADamagedManifestOrAMissingPartStopsTheLogger) {
  const fs::path dir = FreshDir("damaged");
  std::ofstream(dir / "manifest.json") << "{\"complete\": false, ";
  EXPECT_NE(LoggerRefusal(dir).find("manifest.json: not valid JSON"), std::string::npos)
      << LoggerRefusal(dir);
  Manifest died = TwoParts();
  died.complete = false;
  died.stop_utime.reset();
  died.parts.resize(1);
  std::string error;
  ASSERT_TRUE(WriteManifestFile((dir / "manifest.json").string(), died, &error));
  EXPECT_NE(LoggerRefusal(dir).find("orbed-X.lcmlog"), std::string::npos) << LoggerRefusal(dir);
}

}  // namespace
}  // namespace orbed::logger
