// orbed-log against logs whose contents are known by construction (written here with the event-log
// writer; tests/integration/log_tool_integration_test.cc does the same with LCM's own lcm-logger):
//   - info: per channel the counts, bytes, rate (n − 1 over the span) and largest gap, by hand;
//   - check: a damaged range reported at its byte offset, exit 1, the events after it still read;
//   - cut: the events in the time range on the matching channels, nothing else; bad arguments exit 2.
#include "procs/logger/log_tool.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/test_command.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/event_log_writer.h"

namespace orbed::logger {
namespace {

// A: 11 events at 10 Hz from t = 0 (4 bytes each); B: at 0.2 and 0.7 s (2 bytes); C: at 1.0 s.
std::string WriteKnownLog(const std::string& name, std::vector<uint64_t>* offsets = nullptr) {
  const std::string path = ::testing::TempDir() + name;
  EventLogWriter w(path);
  const uint8_t four[4] = {1, 2, 3, 4}, two[2] = {5, 6};
  struct E {
    int64_t t_us;
    const char* channel;
    const uint8_t* data;
    size_t size;
  };
  std::vector<E> events;
  for (int i = 0; i <= 10; ++i) events.push_back({1'000'000 + i * 100'000, "A", four, 4});
  events.push_back({1'200'000, "B", two, 2});
  events.push_back({1'700'000, "B", two, 2});
  events.push_back({2'000'000, "C", four, 1});
  std::sort(events.begin(), events.end(), [](const E& a, const E& b) { return a.t_us < b.t_us; });
  uint64_t offset = 0;
  for (const E& e : events) {
    if (offsets) offsets->push_back(offset);
    offset += w.Write(e.t_us, e.channel, e.data, e.size);
  }
  w.Close();
  return path;
}

TEST(LogTool, InfoCountsRatesAndGapsByHand) {
  const std::string log = WriteKnownLog("known.lcmlog");
  const test::CommandRun r = test::RunCommand(RunLogTool, "orbed-log", {"info", log});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find(": 14 events, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1.000 s, 3 channels, 0 damaged range(s)"), std::string::npos) << r.out;
  // A: 11 events, 44 bytes, 10 per second, 0.1 s apart; B: 2 events 0.5 s apart (rate 2 Hz).
  EXPECT_NE(r.out.find("A                                    11           44      10.0       0.100"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("B                                     2            4       2.0       0.500"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("C                                     1            1       0.0       0.000"),
            std::string::npos)
      << r.out;
}

TEST(LogTool, CheckFindsTheDamageAndReadsPastIt) {
  std::vector<uint64_t> offsets;
  const std::string log = WriteKnownLog("damaged.lcmlog", &offsets);
  EXPECT_EQ(test::RunCommand(RunLogTool, "orbed-log", {"check", log}).code, 0);
  // Overwrite the 5th event's sync word and header with garbage.
  {
    std::fstream f(log, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(offsets[4]));
    const char junk[8] = {'j', 'u', 'n', 'k', 'j', 'u', 'n', 'k'};
    f.write(junk, sizeof(junk));
  }
  const test::CommandRun r = test::RunCommand(RunLogTool, "orbed-log", {"check", log});
  EXPECT_EQ(r.code, 1);
  const std::string range = "damaged bytes " + std::to_string(offsets[4]) + ".." + std::to_string(offsets[5]);
  EXPECT_NE(r.out.find(range), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": 13 events read"), std::string::npos) << r.out;  // all but the damaged one
}

TEST(LogTool, CutKeepsTheTimeRangeAndTheChannels) {
  const std::string log = WriteKnownLog("to_cut.lcmlog");
  const std::string cut = ::testing::TempDir() + "cut.lcmlog";
  const test::CommandRun r = test::RunCommand(
      RunLogTool, "orbed-log", {"cut", log, cut, "--from-s", "0.15", "--to-s", "0.65", "--channels", "A|C"});
  ASSERT_EQ(r.code, 0) << r.err;
  const MappedLog out(cut);
  ASSERT_TRUE(out.ok());
  EventLogScanner scanner = out.Scanner();
  LogEvent e;
  std::vector<int64_t> times;
  while (scanner.Next(&e)) {
    EXPECT_EQ(e.channel, "A");
    EXPECT_EQ(e.event_number, static_cast<int64_t>(times.size()));
    times.push_back(e.timestamp_us);
  }
  EXPECT_EQ(times, (std::vector<int64_t>{1'200'000, 1'300'000, 1'400'000, 1'500'000, 1'600'000}));
  EXPECT_TRUE(scanner.damage().empty());
}

TEST(LogTool, BadArgumentsAndMissingFiles) {
  EXPECT_EQ(test::RunCommand(RunLogTool, "orbed-log", {}).code, 2);
  const std::string log = WriteKnownLog("args.lcmlog");
  EXPECT_EQ(test::RunCommand(RunLogTool, "orbed-log", {"cut", log, "x.lcmlog", "--channels", "(("}).code, 2);
  EXPECT_EQ(
      test::RunCommand(RunLogTool, "orbed-log", {"cut", log, "x.lcmlog", "--from-s", "2", "--to-s", "1"})
          .code,
      2);
  const test::CommandRun missing =
      test::RunCommand(RunLogTool, "orbed-log", {"info", "/nonexistent/x.lcmlog"});
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("nonexistent"), std::string::npos) << missing.err;
  // A file of another kind (text without one event) is refused by every verb, not read as damage.
  const std::string text = testing::TempDir() + "/not_a_log.md";
  std::ofstream(text) << "# a Markdown file\n\nNot an LCM log.\n";
  for (const char* verb : {"info", "check"}) {
    const test::CommandRun r = test::RunCommand(RunLogTool, "orbed-log", {verb, text});
    EXPECT_EQ(r.code, 1) << verb;
    EXPECT_NE(r.err.find("is not an LCM event log"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << verb;
  }
}

}  // namespace
}  // namespace orbed::logger
