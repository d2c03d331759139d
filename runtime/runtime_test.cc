// Unit tests of the process scaffold on memq:// (in-process LCM): typed subscriptions, rejection
// counting, the heartbeat, the fault injection's place in the receive path, and the remembered
// answers of idempotent receivers.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <CLI/CLI.hpp>
#include <orbed/iiwa_command_t.hpp>

#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/validation.h"
#include "runtime/flags.h"
#include "runtime/process.h"
#include "runtime/recent_answers.h"

namespace orbed {
namespace {

TEST(Flags, RecvBufSizeIsAddedOrReplaced) {
  EXPECT_EQ(WithRecvBufSize("udpm://239.255.76.67:7667?ttl=0", 1000),
            "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=1000");
  EXPECT_EQ(WithRecvBufSize("udpm://239.255.76.67:7667", 5), "udpm://239.255.76.67:7667?recv_buf_size=5");
  EXPECT_EQ(WithRecvBufSize("udpm://g:1?recv_buf_size=9&ttl=0", 7), "udpm://g:1?recv_buf_size=7&ttl=0");
  EXPECT_EQ(WithRecvBufSize("memq://", 7), "memq://");
}

TEST(Flags, HelpAndUnknownFlags) {
  CLI::App app{"test"};
  CommonFlags flags("orbed-test");
  AddCommonFlags(&app, &flags);
  const char* argv[] = {"x", "--seed", "42", "--name", "n1", "--duration-s", "2.5"};
  app.parse(7, const_cast<char**>(argv));
  EXPECT_EQ(flags.seed, 42u);
  EXPECT_EQ(flags.name, "n1");
  EXPECT_EQ(flags.duration_s, 2.5);
  CLI::App app2{"test"};
  CommonFlags flags2("orbed-test");
  AddCommonFlags(&app2, &flags2);
  const char* bad[] = {"x", "--log-level", "loud"};
  EXPECT_THROW(app2.parse(3, const_cast<char**>(bad)), CLI::ValidationError);
}

// A process on memq:// receives its own messages: one valid command, one undecodable payload,
// one with a hostile length field, one command the handler rejects. The heartbeat must count
// 4 in, 3 rejected, by reason.
TEST(Process, CountsMessagesRejectionsAndPublishesHeartbeat) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 1.3;
  Process process(flags);
  std::vector<process_status_t> heartbeats;
  int accepted = 0;
  process.Subscribe<process_status_t>(
      channels::kProcessStatus,
      [&](const process_status_t& msg, const std::string&, int64_t) { heartbeats.push_back(msg); });
  process.Subscribe<iiwa_command_t>(channels::kIiwaCommand,
                                    [&](const iiwa_command_t& msg, const std::string& channel, int64_t) {
                                      const std::string error = CheckSize(msg.num_joints, 7, "num_joints");
                                      if (!error.empty()) {
                                        process.Reject(channel + "/num_joints", error);
                                        return;
                                      }
                                      ++accepted;
                                    });
  iiwa_command_t good{};
  good.num_joints = 7;
  good.joint_position.assign(7, 0.0);
  process.lcm().publish(channels::kIiwaCommand, &good);
  iiwa_command_t wrong{};
  wrong.num_joints = 3;
  wrong.joint_position.assign(3, 0.0);
  process.lcm().publish(channels::kIiwaCommand, &wrong);
  const uint8_t garbage[5] = {1, 2, 3, 4, 5};
  process.lcm().publish(channels::kIiwaCommand, garbage, sizeof(garbage));
  // Right fingerprint, then num_joints = -1 (big-endian) and nothing else: the generated decoder
  // would resize a vector to a negative size. It must be a counted rejection, not a crash.
  std::vector<uint8_t> hostile(8 + 8 + 4, 0xff);
  const int64_t hash = iiwa_command_t::getHash();
  for (int i = 0; i < 8; ++i) hostile[i] = static_cast<uint8_t>(hash >> (56 - 8 * i));
  process.lcm().publish(channels::kIiwaCommand, hostile.data(), hostile.size());

  EXPECT_EQ(process.Run(), 0);
  EXPECT_EQ(accepted, 1);
  EXPECT_EQ(process.rejections().total(), 3);
  EXPECT_EQ(process.rejections().counts().at("IIWA_COMMAND/decode/truncated"), 1);  // 5 bytes
  EXPECT_EQ(process.rejections().counts().at("IIWA_COMMAND/decode/count"), 1);      // num_joints -1
  EXPECT_EQ(process.rejections().counts().at("IIWA_COMMAND/num_joints"), 1);
  // Heartbeats: at start, at 1 s, at stop (the stop one is published after the loop and is not
  // received). At least the start and the 1 s heartbeat arrive.
  ASSERT_GE(heartbeats.size(), 2u);
  const process_status_t& last = heartbeats.back();
  EXPECT_EQ(last.name, "orbed-test");
  EXPECT_EQ(last.state, +process_status_t::STATE_RUNNING);
  EXPECT_EQ(last.rejected_inputs, 3);
  EXPECT_EQ(last.num_reasons, 3);  // decode/truncated, decode/count, num_joints
  EXPECT_GE(last.uptime_s, 0.99);
  // 4 commands + the heartbeats received before the last one.
  EXPECT_GE(last.messages_in, 4);
  const process_status_t final_status = process.MakeStatus();
  EXPECT_EQ(final_status.state, +process_status_t::STATE_STOPPING);
  EXPECT_EQ(final_status.messages_out, static_cast<int64_t>(heartbeats.size()) + 1);
}

TEST(Process, TimerFiresAtItsPeriod) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.5;
  Process process(flags);
  int ticks = 0;
  process.AddTimer(0.1, [&] { ++ticks; });
  process.Run();
  // 0.1, 0.2, 0.3, 0.4 (and possibly 0.5) s.
  EXPECT_GE(ticks, 4);
  EXPECT_LE(ticks, 5);
}

// One 0.25 s stall in a 0.1 s timer: the missed ticks run back to back afterwards, so 1 s still
// holds 9 or 10 ticks (skipping would leave 7 or 8).
TEST(Process, TimerCatchesUpAfterAShortStall) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 1.05;
  Process process(flags);
  int ticks = 0;
  process.AddTimer(0.1, [&] {
    if (++ticks == 2) std::this_thread::sleep_for(std::chrono::milliseconds(250));
  });
  process.Run();
  EXPECT_GE(ticks, 9);
  EXPECT_LE(ticks, 10);
}

// A 0.75 s stall in a 0.1 s timer is beyond the catch-up: the deadlines it skipped are counted as
// drops under the timer's name, on the heartbeat too, and every deadline was run or counted.
TEST(Process, TimerSkippedDeadlinesAreCountedDrops) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 1.55;
  Process process(flags);
  int ticks = 0;
  process.AddTimer(
      0.1,
      [&] {
        if (++ticks == 2) std::this_thread::sleep_for(std::chrono::milliseconds(750));
      },
      "STREAM");
  process.Run();
  const auto drops = process.drop_counts();
  ASSERT_EQ(drops.count("timer/STREAM"), 1u);
  const int64_t skipped = drops.at("timer/STREAM");
  EXPECT_GE(skipped, 1);
  EXPECT_EQ(process.dropped(), skipped);
  // 15 deadlines in 1.55 s (0.1 ... 1.5 s), each run or skipped; the last may be pending at the stop.
  EXPECT_GE(ticks + skipped, 14);
  EXPECT_LE(ticks + skipped, 15);
  const orbed::process_status_t status = process.MakeStatus();
  EXPECT_EQ(status.dropped, skipped);
  ASSERT_EQ(status.num_drop_reasons, 1);
  EXPECT_EQ(status.drop_reason[0], "timer/STREAM");
  EXPECT_EQ(status.drop_count[0], skipped);
  EXPECT_EQ(status.rejected_inputs, 0);  // a drop is not a rejection
}

TEST(Process, CountDropSumsPerKeyAndBoundsTheKeys) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  Process process(flags);
  EXPECT_EQ(process.MakeStatus().num_drop_reasons, 0);
  process.CountDrop("HMD_CAMERA/busy");
  process.CountDrop("HMD_CAMERA/busy", 4);
  process.CountDrop("ignored", 0);
  EXPECT_EQ(process.drop_counts(), (std::map<std::string, int64_t>{{"HMD_CAMERA/busy", 5}}));
  for (int i = 0; i < 100; ++i) process.CountDrop("made-up/" + std::to_string(i));
  const auto drops = process.drop_counts();
  EXPECT_EQ(drops.size(), kMaxRejectionClasses);
  EXPECT_EQ(drops.at("HMD_CAMERA/busy"), 5);
  EXPECT_EQ(drops.at(kOtherRejectionClass), 100 - static_cast<int64_t>(kMaxRejectionClasses - 2));
  EXPECT_EQ(process.dropped(), 105);
}

TEST(Process, ExceptionsInTimersAndHandlersAreCountedNotFatal) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.35;
  Process process(flags);
  int ticks = 0;
  process.AddTimer(0.1, [&] {
    ++ticks;
    throw std::runtime_error("bad tick");
  });
  process.Subscribe<iiwa_command_t>(
      channels::kIiwaCommand,
      [&](const iiwa_command_t&, const std::string&, int64_t) { throw std::out_of_range("bad message"); });
  iiwa_command_t cmd{};
  process.lcm().publish(channels::kIiwaCommand, &cmd);
  EXPECT_EQ(process.Run(), 0);
  EXPECT_EQ(ticks, 3);  // it kept ticking after the first exception
  EXPECT_EQ(process.rejections().counts().at("IIWA_COMMAND/handler"), 1);
  EXPECT_EQ(process.rejections().counts().at("timer/1"), 3);  // timer 0 is the heartbeat
}

TEST(Flags, ChaosComesFromTheEnvironmentAndIsChecked) {
  ASSERT_EQ(setenv("ORBED_CHAOS", "drop=0.25,channels=X", 1), 0);
  CommonFlags from_env("orbed-test");
  unsetenv("ORBED_CHAOS");
  EXPECT_EQ(from_env.chaos, "drop=0.25,channels=X");
  EXPECT_EQ(CommonFlags("orbed-test").chaos, "");
  CLI::App app{"test"};
  CommonFlags flags("orbed-test");
  AddCommonFlags(&app, &flags);
  const char* argv[] = {"x", "--chaos", "drop=2"};
  std::ostringstream out, err;
  EXPECT_NE(ParseCommandLine(&app, flags, 3, argv, out, err), std::nullopt);
  EXPECT_NE(err.str().find("--chaos"), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("chaos spec drop: expected one number in [0, 1], got '2'"), std::string::npos)
      << err.str();
}

// The fault injection sits before decoding, on the channels it names only: every IIWA_COMMAND is
// delayed (up to 50 ms, delivered from the Run() loop) and duplicated; PROCESS_STATUS is untouched.
TEST(Process, ChaosDuplicatesAndDelaysTheNamedChannelsOnly) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 1.3;
  flags.chaos = "dup=1,delay_ms=50,channels=IIWA_COMMAND";
  Process process(flags);
  ASSERT_NE(process.chaos(), nullptr);
  std::vector<int64_t> received;
  int heartbeats = 0;
  process.Subscribe<iiwa_command_t>(channels::kIiwaCommand, [&](const iiwa_command_t& msg, const std::string&,
                                                                int64_t) { received.push_back(msg.utime); });
  process.Subscribe<process_status_t>(
      channels::kProcessStatus, [&](const process_status_t&, const std::string&, int64_t) { ++heartbeats; });
  for (int64_t utime : {1, 2, 3}) {
    iiwa_command_t command{};
    command.utime = utime;
    process.lcm().publish(channels::kIiwaCommand, &command);
  }
  EXPECT_EQ(process.Run(), 0);
  std::vector<int64_t> sorted = received;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, (std::vector<int64_t>{1, 1, 2, 2, 3, 3}));
  EXPECT_EQ(process.chaos()->counts().datagrams, 3);
  EXPECT_EQ(process.chaos()->counts().duplicated, 3);
  EXPECT_EQ(process.chaos()->counts().delayed, 3);
  EXPECT_EQ(process.chaos()->counts().dropped, 0);
  EXPECT_GE(heartbeats, 1);  // at start and (unless the machine is very busy) at 1 s: never twice
  EXPECT_LE(heartbeats, 2);
  EXPECT_EQ(process.rejections().total(), 0);  // injected faults are not rejections
}

TEST(Process, ChaosDropsBeforeDecodingAndWithoutASpecThereIsNone) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.2;
  flags.chaos = "drop=1,channels=IIWA_.*";
  Process process(flags);
  int received = 0;
  process.Subscribe<iiwa_command_t>(channels::kIiwaCommand,
                                    [&](const iiwa_command_t&, const std::string&, int64_t) { ++received; });
  const uint8_t garbage[3] = {1, 2, 3};
  process.lcm().publish(channels::kIiwaCommand, garbage, sizeof(garbage));  // dropped, so never refused
  iiwa_command_t command{};
  process.lcm().publish(channels::kIiwaCommand, &command);
  EXPECT_EQ(process.Run(), 0);
  EXPECT_EQ(received, 0);
  EXPECT_EQ(process.chaos()->counts().dropped, 2);
  EXPECT_EQ(process.rejections().total(), 0);
  flags.chaos = "";
  EXPECT_EQ(Process(flags).chaos(), nullptr);
  flags.chaos = "drop=0,channels=.*";
  EXPECT_EQ(Process(flags).chaos(), nullptr);
}

TEST(RecentAnswers, RepeatsTheFirstAnswerAndForgetsTheOldest) {
  RecentAnswers<std::string> answers(2);
  EXPECT_EQ(answers.Find(7), nullptr);
  answers.Remember(7, "seven");
  answers.Remember(0, "no id");  // id 0 is never remembered
  EXPECT_EQ(answers.Find(0), nullptr);
  ASSERT_NE(answers.Find(7), nullptr);
  EXPECT_EQ(*answers.Find(7), "seven");
  answers.Remember(8, "eight");
  answers.Remember(9, "nine");
  EXPECT_EQ(answers.Find(7), nullptr);  // beyond the capacity
  EXPECT_EQ(*answers.Find(8), "eight");
  EXPECT_EQ(*answers.Find(9), "nine");
  EXPECT_EQ(answers.size(), 2u);
}

TEST(Process, MalformedChannelRegexIsAnErrorNotACrash) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  Process process(flags);
  EXPECT_THROW(process.SubscribeRaw("(", [](const lcm::ReceiveBuffer&, const std::string&) {}),
               std::invalid_argument);
}

TEST(Process, BadUrlThrowsNamingIt) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "nosuchprovider://x";
  try {
    Process process(flags);
    FAIL() << "expected a throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nosuchprovider://x"), std::string::npos);
  }
}

}  // namespace
}  // namespace orbed
