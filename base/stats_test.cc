// Oracles: hand-computed ranks and U values, and normal-approximation p-values worked out from the
// standard normal tail (values in the comments), never from this code's output.
#include "base/stats.h"

#include <cmath>

#include <gtest/gtest.h>

namespace orbed::stats {
namespace {

TEST(Stats, MeanMedianStd) {
  const std::vector<double> x{2, 4, 4, 4, 5, 5, 7, 9};
  EXPECT_DOUBLE_EQ(Mean(x), 5.0);
  EXPECT_DOUBLE_EQ(Median(x), 4.5);
  EXPECT_NEAR(StdDev(x), std::sqrt(32.0 / 7.0), 1e-12);  // Σ(x−5)² = 32, N − 1 = 7
  EXPECT_DOUBLE_EQ(Median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(Quantile({1, 2, 3, 4, 5}, 0.25), 2.0);
  EXPECT_DOUBLE_EQ(StdDev({7}), 0.0);
  EXPECT_TRUE(std::isnan(Mean({})));
}

TEST(Stats, AverageRanksShareTies) {
  const std::vector<double> r = AverageRanks({30, 10, 20, 20});
  EXPECT_EQ(r, (std::vector<double>{4, 1, 2.5, 2.5}));
}

// The race of six tortoises (T) and six hares (H) finishing in the order T H H H H H T T T T T H.
// With finishing positions as values, U_T = #(T after H) = 0 + 5 · 5 = 25 and U_H = 36 − 25 = 11;
// the tortoises' rank sum is 1 + 7 + 8 + 9 + 10 + 11 = 46 = 25 + 6·7/2.
TEST(MannWhitney, TortoiseAndHareUValues) {
  const std::vector<double> tortoise{1, 7, 8, 9, 10, 11};
  const std::vector<double> hare{2, 3, 4, 5, 6, 12};
  const MannWhitneyResult r = MannWhitneyU(tortoise, hare);
  ASSERT_TRUE(r.valid);
  EXPECT_DOUBLE_EQ(r.rank_sum_x, 46);
  EXPECT_DOUBLE_EQ(r.u_x, 25);
  EXPECT_DOUBLE_EQ(r.u_y, 11);
  EXPECT_DOUBLE_EQ(r.mean_u, 18);
  EXPECT_DOUBLE_EQ(r.variance_u, 36.0 * 13.0 / 12.0);  // no ties: n_x n_y (n + 1) / 12 = 39
}

// Complete separation, x = 1..10 below y = 11..20: U_x = 0, mean 50, σ² = 100 · 21 / 12 = 175,
// z = (0 − 50 + 0.5) / √175 = −3.74184. Tail Q(3.74184) = φ(z)/z · (1 − z⁻² + 3z⁻⁴ − 15z⁻⁶ + 105z⁻⁸)
// = 3.6354e-4 / 3.74184 · 0.9412 = 9.144e-5, so two-sided p = 1.829e-4 (scipy's asymptotic
// mannwhitneyu gives 1.8267e-4 for the same data).
TEST(MannWhitney, KnownPValueNoTies) {
  std::vector<double> x, y;
  for (int i = 1; i <= 10; ++i) {
    x.push_back(i);
    y.push_back(10 + i);
  }
  const MannWhitneyResult r = MannWhitneyU(x, y);
  ASSERT_TRUE(r.valid);
  EXPECT_DOUBLE_EQ(r.u_x, 0);
  EXPECT_DOUBLE_EQ(r.u_y, 100);
  EXPECT_DOUBLE_EQ(r.variance_u, 175);
  EXPECT_NEAR(r.z, -3.74184, 1e-5);
  EXPECT_NEAR(r.p_two_sided, 1.829e-4, 0.01 * 1.829e-4);
  EXPECT_NEAR(r.p_x_less, 9.144e-5, 0.01 * 9.144e-5);
  EXPECT_GT(r.p_x_greater, 0.9999);
  // Swapping the samples swaps the one-sided alternatives.
  const MannWhitneyResult s = MannWhitneyU(y, x);
  EXPECT_DOUBLE_EQ(s.u_x, 100);
  EXPECT_NEAR(s.p_x_greater, r.p_x_less, 1e-15);
  EXPECT_NEAR(s.p_two_sided, r.p_two_sided, 1e-15);
}

// x = {1, 2, 2}, y = {2, 3, 4}: the three 2s share ranks 2, 3, 4 → 3, so R_x = 1 + 3 + 3 = 7 and
// U_x = 7 − 6 = 1 (x = 1 beats nothing, each x = 2 ties one y: 0.5 + 0.5). One tie group of 3:
// σ² = 9/12 · (7 − (27 − 3)/(6 · 5)) = 0.75 · 6.2 = 4.65. z = (1 − 4.5 + 0.5)/√4.65 = −1.39122,
// Φ(−1.39122) = 1 − (0.91774 + 0.122 · 0.00150) = 0.08208 (table), two-sided p = 0.1642.
TEST(MannWhitney, TieCorrection) {
  const MannWhitneyResult r = MannWhitneyU({1, 2, 2}, {2, 3, 4});
  ASSERT_TRUE(r.valid);
  EXPECT_DOUBLE_EQ(r.u_x, 1);
  EXPECT_NEAR(r.variance_u, 4.65, 1e-12);
  EXPECT_NEAR(r.z, -1.39122, 1e-5);
  EXPECT_NEAR(r.p_two_sided, 0.1642, 0.0015);
  // Without the continuity correction: z = −3.5/√4.65 = −1.62309, Φ = 0.05229 (table: Φ(1.62) =
  // 0.94738, Φ(1.63) = 0.94845), two-sided 0.1046.
  const MannWhitneyResult nc = MannWhitneyU({1, 2, 2}, {2, 3, 4}, false);
  EXPECT_NEAR(nc.p_two_sided, 0.1046, 0.0015);
}

TEST(MannWhitney, Degenerate) {
  EXPECT_FALSE(MannWhitneyU({}, {1, 2}).valid);
  EXPECT_FALSE(MannWhitneyU({3, 3}, {3, 3, 3}).valid);  // all tied: σ = 0
  EXPECT_NEAR(NormalCdf(0), 0.5, 1e-15);
  EXPECT_NEAR(NormalCdf(1.959964), 0.975, 1e-6);
}

}  // namespace
}  // namespace orbed::stats
