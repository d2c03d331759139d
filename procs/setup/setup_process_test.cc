// orbed-setup's shell, what it decides without a bus: the order of the display modes per user seed.
#include "procs/setup/setup_process.h"

#include <algorithm>
#include <cstdint>
#include <set>
#include <vector>

#include <gtest/gtest.h>

namespace orbed::setup {
namespace {

// Every order of the three modes comes from some seed, and a seed always gives the same one.
TEST(SetupConductor, UserSeedsGiveEveryOrder) {
  std::set<std::vector<int8_t>> seen;
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    const std::vector<int8_t> order = ModeOrderForSeed(seed);
    EXPECT_EQ(order, ModeOrderForSeed(seed));
    std::vector<int8_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, (std::vector<int8_t>{0, 1, 2}));
    seen.insert(order);
  }
  EXPECT_EQ(seen.size(), 6u);
}

}  // namespace
}  // namespace orbed::setup
