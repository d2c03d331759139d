// A storm of hostile datagrams into the running testbed (scripts/launch/testbed.yaml through
// orbed-launch, in a private network namespace): tens of thousands of mutated copies of a real
// run's messages (tests/fuzz/corpus/bus, cut from a recorded ViRAAl run by orbed-fuzz-seeds) on
// every channel — bit flips, truncations, extensions, array counts set to 2^31 - 1 or -1. Then:
//   - no process died or was respawned (every heartbeat of a process carries one pid);
//   - each stayed under 256 MB resident at its peak (VmHWM; skipped in sanitizer builds, whose
//     allocator quarantine alone is larger);
//   - the refusals show in PROCESS_STATUS, counted under "<channel>/decode/<why>";
//   - a ViRAAl run (orbed-scenario) started afterwards against the same testbed completes.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>

#include "base/proc_stats.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

namespace fs = std::filesystem;

struct Sample {
  std::string channel;
  std::vector<uint8_t> bytes;
};

// The corpus files: the channel's index in kAllChannels, then the datagram.
std::vector<Sample> LoadRecordedSamples() {
  std::vector<Sample> samples;
  for (const auto& entry : fs::directory_iterator(SourcePath("tests/fuzz/corpus/bus"))) {
    std::ifstream in(entry.path(), std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.size() < 2) continue;
    samples.push_back({channels::kAllChannels[bytes[0] % std::size(channels::kAllChannels)],
                       std::vector<uint8_t>(bytes.begin() + 1, bytes.end())});
  }
  return samples;
}

std::vector<uint8_t> Mutate(const std::vector<uint8_t>& original, std::mt19937& rng) {
  std::vector<uint8_t> bytes = original;
  const int edits = 1 + static_cast<int>(rng() % 3);
  for (int e = 0; e < edits && !bytes.empty(); ++e) {
    const size_t at = rng() % bytes.size();
    switch (rng() % 6) {
      case 0:  // bit flips
        bytes[at] ^= static_cast<uint8_t>(1u << (rng() % 8));
        break;
      case 1:  // truncation
        bytes.resize(at);
        break;
      case 2:  // extension
        for (int i = 0; i < 1 + static_cast<int>(rng() % 16); ++i)
          bytes.push_back(static_cast<uint8_t>(rng()));
        break;
      case 3:    // a huge count (int32 2^31 - 1) anywhere after the fingerprint
      case 4: {  // a negative one
        if (bytes.size() < 12) break;
        const size_t pos = 8 + rng() % (bytes.size() - 11);
        const uint8_t fill[2][4] = {{0x7f, 0xff, 0xff, 0xff}, {0xff, 0xff, 0xff, 0xff}};
        const uint8_t* value = fill[rng() % 2];
        std::copy(value, value + 4, bytes.begin() + static_cast<long>(pos));
        break;
      }
      default:  // a random byte
        bytes[at] = static_cast<uint8_t>(rng());
    }
  }
  return bytes;
}

const char* const kTestbed[] = {"logger", "sim", "registration", "hmd", "monitor"};

TEST(Storm, MutatedTrafficIsRefusedAndTheTestbedKeepsWorking) {
  const std::vector<Sample> samples = LoadRecordedSamples();
  ASSERT_GE(samples.size(), 20u) << "tests/fuzz/corpus/bus holds too few recorded messages";
  std::set<std::string> sampled_channels;
  for (const Sample& s : samples) sampled_channels.insert(s.channel);

  const std::string log_dir = MakeTempDir("storm");
  BusWatcher watcher;
  watcher.Start();
  RunningProcess launcher(
      {BinPath("orbed-launch"), SourcePath("scripts/launch/testbed.yaml"), "--duration-s", "600"},
      {{"ORBED_LOG_DIR", log_dir}});
  // The testbed's own heartbeats are those from the launcher's children (the storm replays
  // heartbeats of the recorded run, mutated, under the same names).
  std::map<std::string, pid_t> children;
  auto heartbeat_of = [&](const std::string& name) -> std::unique_ptr<orbed::process_status_t> {
    const auto beats = watcher.Heartbeats(name);
    for (auto it = beats.rbegin(); it != beats.rend(); ++it) {
      if (children.count(name) > 0 && it->status.pid == children[name]) {
        return std::make_unique<orbed::process_status_t>(it->status);
      }
    }
    return nullptr;
  };
  ASSERT_TRUE(WaitFor(
      [&] {
        children = ChildrenByName(launcher.pid());
        for (const char* name : kTestbed) {
          const auto beat = heartbeat_of(name);
          if (!beat || beat->state != orbed::process_status_t::STATE_RUNNING) return false;
        }
        return true;
      },
      120))
      << "the testbed did not come up";

  // The storm: 30000 mutated datagrams, images (the largest) one in fifty. Paced at about 10 per
  // millisecond so that most reach the processes rather than the kernel's drop counter.
  lcm::LCM publisher;
  ASSERT_TRUE(publisher.good());
  std::mt19937 rng(2026);
  std::vector<const Sample*> small, large;
  for (const Sample& s : samples) (s.bytes.size() > 4096 ? large : small).push_back(&s);
  ASSERT_FALSE(small.empty());
  constexpr int kStorm = 30000;
  for (int i = 0; i < kStorm; ++i) {
    const bool pick_large = !large.empty() && rng() % 50 == 0;
    const Sample& sample = pick_large ? *large[rng() % large.size()] : *small[rng() % small.size()];
    const std::vector<uint8_t> bytes = Mutate(sample.bytes, rng);
    publisher.publish(sample.channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
    if (i % 10 == 9)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));  // pacing, not synchronisation
  }

  // Refusals appear in the heartbeats of every process that subscribes to something.
  auto decode_refusals = [&](const std::string& name) {
    const auto beat = heartbeat_of(name);
    int64_t total = 0;
    if (!beat) return total;
    for (size_t i = 0; i < beat->reject_reason.size(); ++i) {
      if (beat->reject_reason[i].find("/decode/") != std::string::npos) total += beat->reject_count[i];
    }
    return total;
  };
  for (const char* name : {"sim", "registration", "hmd", "monitor"}) {
    EXPECT_TRUE(WaitFor([&] { return decode_refusals(name) > 100; }, 30))
        << name << " shows " << decode_refusals(name) << " decode refusals";
  }

  // Nobody died: the launcher's children are the ones it started, each still alive.
  const bool sanitized = std::getenv("ORBED_SANITIZED") != nullptr;
  EXPECT_EQ(ChildrenByName(launcher.pid()), children) << "a process died and was respawned";
  for (const char* name : kTestbed) {
    const int pid = children[name];
    ASSERT_EQ(::kill(pid, 0), 0) << name << " (pid " << pid << ") is gone";
    const long peak_kb = static_cast<long>(ProcStatusKb(pid, "VmHWM"));
    std::printf("storm: %-12s pid %d peak resident %ld MB, %lld decode refusals\n", name, pid, peak_kb / 1024,
                static_cast<long long>(decode_refusals(name)));
    EXPECT_TRUE(sanitized || peak_kb < 256 * 1024) << name << " peaked at " << peak_kb << " kB";
  }
  EXPECT_TRUE(launcher.running());

  // The testbed still works: a whole ViRAAl run against it.
  RunningProcess scenario({BinPath("orbed-scenario"), "--run-id", "after-storm", "--results-dir", log_dir});
  ASSERT_TRUE(scenario.Wait(240)) << "the ViRAAl run after the storm did not finish";
  EXPECT_EQ(scenario.exit_code(), 0);
  const YAML::Node results = YAML::LoadFile(log_dir + "/results.json");
  EXPECT_EQ(results["status"].as<std::string>(), "ok");
  EXPECT_EQ(results["sessions"].size(), 2u);

  launcher.Signal(SIGINT);
  EXPECT_TRUE(launcher.Wait(60));
}

}  // namespace
}  // namespace orbed::testing
