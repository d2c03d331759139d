// The pose history against hand-placed samples: exact and nearest matches, the window, the bound,
// lost tracking and a clock that went back.
#include "procs/hl2ss/pose_history.h"

#include <gtest/gtest.h>

namespace orbed::hl2ss {
namespace {

Eigen::Isometry3d At(double x) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation().x() = x;
  return X;
}

double XOf(const std::optional<Eigen::Isometry3d>& X) { return X ? X->translation().x() : -1.0; }

TEST(PoseHistory, ExactOrNearestWithinTheWindow) {
  PoseHistory h(600, 100);
  EXPECT_FALSE(h.Find(0));
  for (int i = 0; i < 5; ++i) h.Add({1000 + 200 * i, At(i), true});  // 1000, 1200, …, 1800
  EXPECT_EQ(XOf(h.Find(1400)), 2);
  EXPECT_EQ(XOf(h.Find(1499)), 2);
  EXPECT_EQ(XOf(h.Find(1500)), 2);  // halfway: the earlier
  EXPECT_EQ(XOf(h.Find(1501)), 3);
  EXPECT_EQ(XOf(h.Find(900)), 0);  // 100 before the oldest: inside the window
  EXPECT_FALSE(h.Find(899));       // 101 before
  EXPECT_EQ(XOf(h.Find(1900)), 4);
  EXPECT_FALSE(h.Find(1901));
  EXPECT_FALSE(h.Find(INT64_MIN));
  EXPECT_FALSE(h.Find(INT64_MAX / 2));
}

TEST(PoseHistory, BoundedLostAndRestarted) {
  PoseHistory h(3, 10);
  for (int i = 0; i < 5; ++i) h.Add({100 * i, At(i), i != 3});
  EXPECT_EQ(h.size(), 3u);
  EXPECT_FALSE(h.Find(100));  // dropped: only 200, 300, 400 kept
  EXPECT_EQ(XOf(h.Find(200)), 2);
  EXPECT_FALSE(h.Find(300));  // tracking lost then
  h.Add({400, At(7), true});  // the same utime again: replaces
  EXPECT_EQ(h.size(), 3u);
  EXPECT_EQ(XOf(h.Find(400)), 7);
  h.Add({50, At(9), true});  // the clock went back: history restarts
  EXPECT_EQ(h.size(), 1u);
  EXPECT_EQ(XOf(h.Find(50)), 9);
  EXPECT_FALSE(h.Find(400));
}

}  // namespace
}  // namespace orbed::hl2ss
