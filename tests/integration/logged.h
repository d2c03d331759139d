#pragma once
/// @file
/// Reading a run's recorded messages back in integration tests: Logged<Msg>(run folder, channel).

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "procs/logger/event_log_reader.h"
#include "procs/logger/manifest.h"

namespace orbed::testing {

/// Every message on `channel` in a run folder's log (every part its manifest.json lists), decoded
/// in log order; a message that does not decode whole is a test failure.
template <class Msg>
std::vector<Msg> Logged(const std::string& log_dir, const std::string& channel) {
  std::vector<Msg> out;
  const logger::Manifest parts = logger::ReadManifestFile(log_dir + "/manifest.json");
  for (const logger::ManifestPart& part : parts.parts) {
    const logger::MappedLog log(log_dir + "/" + part.file);
    EXPECT_TRUE(log.ok()) << log.error();
    logger::EventLogScanner scanner = log.Scanner();
    logger::LogEvent event;
    while (scanner.Next(&event)) {
      if (event.channel != channel) continue;
      Msg msg{};
      EXPECT_EQ(msg.decode(event.data, 0, static_cast<int>(event.size)), static_cast<int>(event.size))
          << channel;
      out.push_back(std::move(msg));
    }
  }
  return out;
}

}  // namespace orbed::testing
