// EventLogScanner against logs written by LCM's own writer (lcm::LogFile), whole and damaged.
#include "procs/logger/event_log_reader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <lcm/lcm-cpp.hpp>
#include <random>
#include <string>
#include <vector>

namespace orbed::logger {
namespace {

struct Written {
  std::string channel;
  std::string data;
  int64_t timestamp_us;
};

// Writes `events` with lcm::LogFile and returns the file's bytes.
std::vector<uint8_t> WriteWithLcm(const std::vector<Written>& events) {
  char path[] = "/tmp/orbed_reader_testXXXXXX";
  const int fd = mkstemp(path);
  EXPECT_GE(fd, 0);
  close(fd);
  {
    lcm::LogFile log(path, "w");
    EXPECT_TRUE(log.good());
    for (size_t i = 0; i < events.size(); ++i) {
      lcm::LogEvent event{};
      event.eventnum = static_cast<int64_t>(i);
      event.timestamp = events[i].timestamp_us;
      event.channel = events[i].channel;
      event.datalen = static_cast<int32_t>(events[i].data.size());
      event.data = const_cast<char*>(events[i].data.data());
      EXPECT_EQ(log.writeEvent(&event), 0);
    }
  }
  std::ifstream in(path, std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::remove(path);
  return bytes;
}

std::vector<Written> SomeEvents() {
  std::vector<Written> events;
  for (int i = 0; i < 20; ++i) {
    events.push_back({"CHANNEL_" + std::to_string(i % 3), std::string(static_cast<size_t>(10 + 37 * i), 'a' + i),
                      1700000000000000 + 1000 * i});
  }
  events.push_back({"EMPTY", "", 1700000000100000});
  return events;
}

std::vector<LogEvent> ReadAll(EventLogScanner& scanner) {
  std::vector<LogEvent> events;
  LogEvent event;
  while (scanner.Next(&event)) events.push_back(event);
  return events;
}

TEST(EventLogScanner, ReadsWhatLcmWrote) {
  const std::vector<Written> written = SomeEvents();
  const std::vector<uint8_t> bytes = WriteWithLcm(written);
  EventLogScanner scanner(bytes.data(), bytes.size());
  const std::vector<LogEvent> read = ReadAll(scanner);
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].event_number, static_cast<int64_t>(i));
    EXPECT_EQ(read[i].timestamp_us, written[i].timestamp_us);
    EXPECT_EQ(read[i].channel, written[i].channel);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(read[i].data), read[i].size), written[i].data);
  }
  EXPECT_TRUE(scanner.damage().empty());
}

TEST(EventLogScanner, SkipsACorruptedEventAndReportsItsOffset) {
  const std::vector<Written> written = SomeEvents();
  std::vector<uint8_t> bytes = WriteWithLcm(written);
  // Where event 5 starts: 28-byte header + channel + data per event.
  size_t offset = 0;
  for (int i = 0; i < 5; ++i) offset += 28 + written[i].channel.size() + written[i].data.size();
  bytes[offset + 22] = 0x7f;  // its channel length becomes huge
  EventLogScanner scanner(bytes.data(), bytes.size());
  const std::vector<LogEvent> read = ReadAll(scanner);
  ASSERT_EQ(read.size(), written.size() - 1);
  EXPECT_EQ(read[4].event_number, 4);
  EXPECT_EQ(read[5].event_number, 6);  // resynced on event 6's sync word
  ASSERT_EQ(scanner.damage().size(), 1u);
  EXPECT_EQ(scanner.damage()[0].offset, offset);
  EXPECT_EQ(scanner.damage()[0].bytes, 28 + written[5].channel.size() + written[5].data.size());
  EXPECT_NE(scanner.damage()[0].reason.find("channel length"), std::string::npos) << scanner.damage()[0].reason;
}

TEST(EventLogScanner, ACutLogEndsAtItsLastWholeEventAndGarbageBeforeIsSkipped) {
  const std::vector<Written> written = SomeEvents();
  std::vector<uint8_t> bytes = WriteWithLcm(written);
  bytes.resize(bytes.size() - 3);  // the last event loses its tail
  bytes.insert(bytes.begin(), {0xED, 0xA1, 0x00, 0x01, 0x02});
  EventLogScanner scanner(bytes.data(), bytes.size());
  const std::vector<LogEvent> read = ReadAll(scanner);
  ASSERT_EQ(read.size(), written.size() - 1);
  EXPECT_EQ(read.front().event_number, 0);
  ASSERT_EQ(scanner.damage().size(), 2u);
  EXPECT_EQ(scanner.damage()[0].offset, 0u);
  EXPECT_EQ(scanner.damage()[0].bytes, 5u);
  EXPECT_EQ(scanner.damage()[1].offset + scanner.damage()[1].bytes, bytes.size());
  EXPECT_NE(scanner.damage()[1].reason.find("cut short"), std::string::npos) << scanner.damage()[1].reason;
}

// Random damage to sync words, channel lengths and payloads: every event the scanner returns lies
// within the bytes, and every event whose bytes were untouched comes back intact. (A length field
// changed to another plausible length cannot be detected in this format, so it is not drawn.)
TEST(EventLogScanner, RandomDamageNeverLosesAnUntouchedEvent) {
  const std::vector<Written> written = SomeEvents();
  const std::vector<uint8_t> clean = WriteWithLcm(written);
  std::vector<size_t> starts;
  size_t offset = 0;
  for (const Written& w : written) {
    starts.push_back(offset);
    offset += 28 + w.channel.size() + w.data.size();
  }
  std::mt19937 rng(7);
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<uint8_t> bytes = clean;
    std::vector<bool> touched(written.size(), false);
    for (int e = 0; e < 3; ++e) {
      const size_t i = rng() % written.size();
      touched[i] = true;
      switch (rng() % 3) {
        case 0:
          bytes[starts[i] + rng() % 4] ^= static_cast<uint8_t>(1 + rng() % 255);  // sync word
          break;
        case 1:
          bytes[starts[i] + 22] = 0x7f;  // channel length far beyond any channel
          break;
        default:
          if (!written[i].data.empty()) {
            bytes[starts[i] + 28 + written[i].channel.size() + rng() % written[i].data.size()] ^= 0x20;
          }
      }
    }
    EventLogScanner scanner(bytes.data(), bytes.size());
    std::vector<bool> seen(written.size(), false);
    LogEvent event;
    while (scanner.Next(&event)) {
      ASSERT_LE(event.offset + 28 + event.channel.size() + event.size, bytes.size());
      for (size_t i = 0; i < starts.size(); ++i) {
        if (event.offset == starts[i] && !touched[i]) {
          EXPECT_EQ(std::string(reinterpret_cast<const char*>(event.data), event.size), written[i].data);
          seen[i] = true;
        }
      }
    }
    for (size_t i = 0; i < written.size(); ++i) {
      if (!touched[i]) EXPECT_TRUE(seen[i]) << "trial " << trial << " event " << i;
    }
  }
}

TEST(MappedLog, MissingFileIsAnErrorAndAnEmptyFileHasNoEvents) {
  MappedLog missing("/nonexistent/orbed.lcmlog");
  EXPECT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("/nonexistent/orbed.lcmlog"), std::string::npos);
  char path[] = "/tmp/orbed_empty_logXXXXXX";
  const int fd = mkstemp(path);
  close(fd);
  MappedLog empty(path);
  EXPECT_TRUE(empty.ok()) << empty.error();
  EventLogScanner scanner = empty.Scanner();
  LogEvent event;
  EXPECT_FALSE(scanner.Next(&event));
  std::remove(path);
}

}  // namespace
}  // namespace orbed::logger
