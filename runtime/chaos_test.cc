// The fault injection's pure core: the spec's syntax and errors, seeded draws (a pure function of
// seed, receiver, channel and index), rates within binomial bounds, and the queue's delivery
// order for drops, duplicates, delays and reorders on an emulated clock.
#include "runtime/chaos.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/hash.h"

namespace orbed {
namespace {

std::string ErrorOf(const std::string& spec) {
  try {
    ParseChaosSpec(spec);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ChaosSpec, ParsesEveryKeyAndRoundTrips) {
  const ChaosSpec spec =
      ParseChaosSpec("drop=0.1,dup=0.05,delay_ms=30,reorder=0.02,seed=7,channels=SESSION_CONTROL|A{1,2}");
  EXPECT_EQ(spec.drop, 0.1);
  EXPECT_EQ(spec.dup, 0.05);
  EXPECT_EQ(spec.delay_ms, 30);
  EXPECT_EQ(spec.reorder, 0.02);
  EXPECT_EQ(spec.seed, 7u);
  EXPECT_EQ(spec.channels, "SESSION_CONTROL|A{1,2}");  // the rest of the spec, commas included
  EXPECT_TRUE(spec.active());
  const ChaosSpec again = ParseChaosSpec(FormatChaosSpec(spec));
  EXPECT_EQ(FormatChaosSpec(again), FormatChaosSpec(spec));
  EXPECT_EQ(FormatChaosSpec(spec),
            "drop=0.1,dup=0.05,delay_ms=30,reorder=0.02,seed=7,channels=SESSION_CONTROL|A{1,2}");
}

TEST(ChaosSpec, EmptyOrAllZeroInjectsNothing) {
  EXPECT_FALSE(ParseChaosSpec("").active());
  EXPECT_FALSE(ParseChaosSpec("seed=3,channels=X").active());
  EXPECT_FALSE(ParseChaosSpec("drop=0,dup=0,delay_ms=0,reorder=0").active());
  EXPECT_EQ(ParseChaosSpec("").channels, ".*");
  EXPECT_TRUE(ParseChaosSpec("delay_ms=1").active());
}

TEST(ChaosSpec, ErrorsNameTheKey) {
  EXPECT_EQ(ErrorOf("drop=1.5"), "chaos spec drop: expected one number in [0, 1], got '1.5'");
  EXPECT_EQ(ErrorOf("dup=-0.1"), "chaos spec dup: expected one number in [0, 1], got '-0.1'");
  EXPECT_EQ(ErrorOf("delay_ms=20000"), "chaos spec delay_ms: expected one number in [0, 10000], got '20000'");
  EXPECT_NE(ErrorOf("reorder=x").find("chaos spec reorder"), std::string::npos) << ErrorOf("reorder=x");
  EXPECT_EQ(ErrorOf("seed=-1"), "chaos spec seed: expected an unsigned integer, got '-1'");
  EXPECT_EQ(ErrorOf("seed=1x"), "chaos spec seed: expected an unsigned integer, got '1x'");
  EXPECT_EQ(ErrorOf("lose=0.1"),
            "chaos spec: unknown key 'lose' (keys: drop, dup, delay_ms, reorder, seed, channels)");
  EXPECT_EQ(ErrorOf("drop"),
            "chaos spec: expected key=value, got 'drop' (keys: drop, dup, delay_ms, reorder, "
            "seed, channels)");
  EXPECT_EQ(ErrorOf("drop=0.1,"), "chaos spec: trailing comma");
  EXPECT_NE(ErrorOf("channels=(").find("chaos spec channels: invalid regular expression '('"),
            std::string::npos);
  EXPECT_EQ(ErrorOf("channels="), "chaos spec channels: empty regular expression");
}

TEST(ChaosDraws, AreAPureFunctionOfSeedReceiverChannelAndIndex) {
  const ChaosSpec spec = ParseChaosSpec("drop=0.5,dup=0.5,reorder=0.5,delay_ms=10");
  const uint64_t a = Fnv1a64("sim"), b = Fnv1a64("hmd"), c = Fnv1a64("IIWA_COMMAND");
  int same_receiver = 0, other_receiver = 0, other_seed = 0;
  ChaosSpec reseeded = spec;
  reseeded.seed = 2;
  for (uint64_t k = 0; k < 1000; ++k) {
    const ChaosFate one = DrawChaosFate(spec, a, c, k), two = DrawChaosFate(spec, a, c, k);
    same_receiver += one.drop == two.drop && one.duplicate == two.duplicate && one.reorder == two.reorder &&
                     one.delay_s == two.delay_s;
    other_receiver += one.drop == DrawChaosFate(spec, b, c, k).drop;
    other_seed += one.drop == DrawChaosFate(reseeded, a, c, k).drop;
  }
  EXPECT_EQ(same_receiver, 1000);
  // Independent draws agree about half the time (p = 0.5): well inside 350..650.
  EXPECT_GT(other_receiver, 350);
  EXPECT_LT(other_receiver, 650);
  EXPECT_GT(other_seed, 350);
  EXPECT_LT(other_seed, 650);
}

// Counts of n draws with probability p lie within 5 standard deviations of n p (a bound a correct
// generator exceeds with probability < 1e-6), and the draws of different purposes are independent.
TEST(ChaosDraws, RatesAreWithinBinomialBounds) {
  const ChaosSpec spec = ParseChaosSpec("drop=0.1,dup=0.05,reorder=0.02,delay_ms=30");
  const int n = 20000;
  int drops = 0, dups = 0, reorders = 0, drop_and_dup = 0;
  double delay_sum = 0, delay_max = 0, delay_min = 1;
  for (int k = 0; k < n; ++k) {
    const ChaosFate fate = DrawChaosFate(spec, Fnv1a64("registration"), Fnv1a64("SESSION_CONTROL"), k);
    drops += fate.drop;
    dups += fate.duplicate;
    reorders += fate.reorder;
    drop_and_dup += fate.drop && fate.duplicate;
    delay_sum += fate.delay_s;
    delay_max = std::max(delay_max, fate.delay_s);
    delay_min = std::min(delay_min, fate.delay_s);
  }
  const auto expect_binomial = [n](int count, double p, const char* what) {
    const double sigma = std::sqrt(n * p * (1 - p));
    EXPECT_NEAR(count, n * p, 5 * sigma) << what;
  };
  expect_binomial(drops, 0.1, "drop");
  expect_binomial(dups, 0.05, "dup");
  expect_binomial(reorders, 0.02, "reorder");
  expect_binomial(drop_and_dup, 0.1 * 0.05, "drop and dup together");
  // Delays are uniform on [0, 30 ms]: mean 15 ms, standard deviation of the mean 30/sqrt(12 n) ms.
  EXPECT_NEAR(delay_sum / n, 0.015, 5 * 0.030 / std::sqrt(12.0 * n));
  EXPECT_GE(delay_min, 0.0);
  EXPECT_LE(delay_max, 0.030);
  EXPECT_GT(delay_max, 0.0299);
}

// A queue on one channel, fed datagrams numbered by their payload's first byte.
struct Feed {
  explicit Feed(const std::string& spec) : queue(ParseChaosSpec(spec), "test") {}
  void Arrive(int number, double t_s, const std::string& channel = "CH") {
    ASSERT_TRUE(queue.Applies(channel));
    queue.Receive({0, channel, {static_cast<uint8_t>(number)}, 1000 + number}, t_s);
  }
  std::vector<int> Take(double t_s) {
    std::vector<int> out;
    for (const auto& d : queue.TakeDue(t_s)) out.push_back(d.data[0]);
    return out;
  }
  ChaosQueue queue;
};

TEST(ChaosQueue, OnlyMatchingChannelsOfAnActiveSpecApply) {
  ChaosQueue queue(ParseChaosSpec("drop=1,channels=SESSION_CONTROL|ALIGNMENT_TRIAL"), "p");
  EXPECT_TRUE(queue.Applies("SESSION_CONTROL"));
  EXPECT_TRUE(queue.Applies("ALIGNMENT_TRIAL"));
  EXPECT_FALSE(queue.Applies("SESSION_CONTROL_X"));  // the whole name must match
  EXPECT_FALSE(queue.Applies("IIWA_STATUS"));
  ChaosQueue inactive(ParseChaosSpec("seed=4"), "p");
  EXPECT_FALSE(inactive.Applies("SESSION_CONTROL"));
  // Bounded: beyond kMaxChannels distinct names a new channel passes unharmed.
  ChaosQueue all(ParseChaosSpec("drop=1"), "p");
  for (size_t i = 0; i < ChaosQueue::kMaxChannels; ++i) EXPECT_TRUE(all.Applies("C" + std::to_string(i)));
  EXPECT_FALSE(all.Applies("ONE_MORE"));
  EXPECT_TRUE(all.Applies("C0"));
}

TEST(ChaosQueue, WithoutFaultsEverythingIsDueAtOnceInOrder) {
  ChaosQueue inactive(ParseChaosSpec("drop=0,dup=0,delay_ms=0,reorder=0"), "test");
  EXPECT_FALSE(inactive.Applies("CH"));
  Feed lossless("drop=1e-9");  // active, and none of the first 10 is dropped
  for (int i = 0; i < 10; ++i) lossless.Arrive(i, 1.0);
  EXPECT_EQ(lossless.Take(1.0), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(lossless.queue.counts().datagrams, 10);
  EXPECT_EQ(lossless.queue.counts().dropped, 0);
  EXPECT_TRUE(std::isinf(lossless.queue.NextDue()));
}

TEST(ChaosQueue, DropsAndDuplicates) {
  Feed drop("drop=1");
  for (int i = 0; i < 5; ++i) drop.Arrive(i, 0.0);
  EXPECT_TRUE(drop.Take(10.0).empty());
  EXPECT_EQ(drop.queue.counts().dropped, 5);
  Feed dup("dup=1");
  for (int i = 0; i < 3; ++i) dup.Arrive(i, 0.0);
  EXPECT_EQ(dup.Take(0.0), (std::vector<int>{0, 0, 1, 1, 2, 2}));
  EXPECT_EQ(dup.queue.counts().duplicated, 3);
  // The receive utime travels with the datagram and its copy.
  dup.Arrive(7, 1.0);
  for (const auto& d : dup.queue.TakeDue(1.0)) EXPECT_EQ(d.recv_utime, 1007);
}

TEST(ChaosQueue, AReorderedDatagramSwapsWithTheNextOrWaitsAtMostTheHold) {
  Feed feed("reorder=1");
  feed.Arrive(0, 0.0);
  EXPECT_TRUE(feed.Take(0.0).empty());  // held for the next one
  EXPECT_DOUBLE_EQ(feed.queue.NextDue(), ChaosQueue::kReorderMaxHold_s);
  feed.Arrive(1, 0.1);
  feed.Arrive(2, 0.2);
  feed.Arrive(3, 0.3);
  EXPECT_EQ(feed.Take(0.3), (std::vector<int>{1, 0, 3, 2}));
  feed.Arrive(4, 1.0);  // nothing follows
  EXPECT_TRUE(feed.Take(1.0 + ChaosQueue::kReorderMaxHold_s - 1e-6).empty());
  EXPECT_EQ(feed.Take(1.0 + ChaosQueue::kReorderMaxHold_s), (std::vector<int>{4}));
  EXPECT_EQ(feed.queue.counts().reordered, 3);  // 0, 2 and 4 were held; 1 and 3 released them
  // A held datagram is released by the next arrival even when that one is dropped.
  Feed both("reorder=1,drop=0.5,seed=3");
  std::vector<int> delivered;
  for (int i = 0; i < 200; ++i) {
    both.Arrive(i, i * 0.01);
    for (int d : both.Take(i * 0.01)) delivered.push_back(d);
  }
  for (int d : both.Take(100.0)) delivered.push_back(d);
  EXPECT_EQ(static_cast<int64_t>(delivered.size()), 200 - both.queue.counts().dropped);
  EXPECT_EQ(std::set<int>(delivered.begin(), delivered.end()).size(), delivered.size());
}

// Delays: every datagram comes out once, not before it arrived and not later than delay_ms after,
// in order of due time; datagrams closer than delay_ms overtake each other.
TEST(ChaosQueue, DelayedDatagramsComeOutInDueOrderWithinTheDelay) {
  Feed feed("delay_ms=30,seed=11");
  const double period_s = 0.001;
  std::vector<std::pair<int, double>> delivered;  // number, time taken
  double t_s = 0;
  for (int i = 0; i < 200; ++i, t_s += period_s) {
    feed.Arrive(i, t_s);
    for (int d : feed.Take(t_s)) delivered.push_back({d, t_s});
  }
  while (std::isfinite(feed.queue.NextDue())) {
    t_s = feed.queue.NextDue();
    for (int d : feed.Take(t_s)) delivered.push_back({d, t_s});
  }
  ASSERT_EQ(delivered.size(), 200u);
  std::set<int> seen;
  int overtaken = 0;
  for (size_t j = 0; j < delivered.size(); ++j) {
    const auto [number, taken_s] = delivered[j];
    EXPECT_TRUE(seen.insert(number).second) << number;
    const double arrived_s = number * period_s;
    EXPECT_GE(taken_s, arrived_s - 1e-12) << number;
    EXPECT_LE(taken_s, arrived_s + 0.030 + period_s) << number;
    if (j > 0 && number < delivered[j - 1].first) ++overtaken;
  }
  EXPECT_GT(overtaken, 10);
  EXPECT_EQ(feed.queue.counts().delayed, 200);
}

}  // namespace
}  // namespace orbed
