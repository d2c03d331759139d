#include "base/stats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace orbed::stats {

double Mean(const std::vector<double>& x) {
  if (x.empty()) return std::numeric_limits<double>::quiet_NaN();
  return std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
}

double Median(std::vector<double> x) { return Quantile(std::move(x), 0.5); }

double StdDev(const std::vector<double>& x) {
  if (x.empty()) return std::numeric_limits<double>::quiet_NaN();
  if (x.size() == 1) return 0.0;
  const double m = Mean(x);
  double ss = 0;
  for (double v : x) ss += (v - m) * (v - m);
  return std::sqrt(ss / static_cast<double>(x.size() - 1));
}

double Quantile(std::vector<double> x, double q) {
  if (x.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(x.begin(), x.end());
  const double h = std::clamp(q, 0.0, 1.0) * static_cast<double>(x.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, x.size() - 1);
  return x[lo] + (h - static_cast<double>(lo)) * (x[hi] - x[lo]);
}

std::vector<double> AverageRanks(const std::vector<double>& x) {
  std::vector<std::size_t> order(x.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return x[a] < x[b]; });
  std::vector<double> ranks(x.size());
  std::size_t i = 0;
  while (i < order.size()) {
    std::size_t j = i;
    while (j + 1 < order.size() && x[order[j + 1]] == x[order[i]]) ++j;
    const double r = 0.5 * static_cast<double>(i + j) + 1.0;  // mean of ranks i+1 .. j+1
    for (std::size_t k = i; k <= j; ++k) ranks[order[k]] = r;
    i = j + 1;
  }
  return ranks;
}

double NormalCdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

namespace {

// A rank statistic's normal approximation: z with the continuity correction (0.5 toward the mean)
// and the two- and one-sided p-values. variance > 0.
struct NormalApproximation {
  double z, p_two_sided, p_less, p_greater;
};

NormalApproximation ApproximateByNormal(double statistic, double mean, double variance,
                                        bool continuity_correction) {
  const double sigma = std::sqrt(variance);
  const double c = continuity_correction ? 0.5 : 0.0;
  const double d = statistic - mean;
  const double d_toward_zero = d > 0 ? std::max(0.0, d - c) : std::min(0.0, d + c);
  NormalApproximation a;
  a.z = d_toward_zero / sigma;
  a.p_two_sided = std::min(1.0, 2.0 * NormalCdf(-std::abs(a.z)));
  a.p_less = NormalCdf((d + c) / sigma);
  a.p_greater = 1.0 - NormalCdf((d - c) / sigma);
  return a;
}

}  // namespace

MannWhitneyResult MannWhitneyU(const std::vector<double>& x, const std::vector<double>& y,
                               bool continuity_correction) {
  MannWhitneyResult r;
  r.n_x = static_cast<int>(x.size());
  r.n_y = static_cast<int>(y.size());
  if (x.empty() || y.empty()) return r;
  std::vector<double> all(x);
  all.insert(all.end(), y.begin(), y.end());
  const std::vector<double> ranks = AverageRanks(all);
  for (std::size_t i = 0; i < x.size(); ++i) r.rank_sum_x += ranks[i];
  const double nx = r.n_x, ny = r.n_y, n = nx + ny;
  r.u_x = r.rank_sum_x - nx * (nx + 1) / 2;
  r.u_y = nx * ny - r.u_x;
  r.mean_u = nx * ny / 2;

  // Tie groups from the sorted pooled sample.
  std::vector<double> sorted(all);
  std::sort(sorted.begin(), sorted.end());
  double tie_sum = 0;
  for (std::size_t i = 0; i < sorted.size();) {
    std::size_t j = i;
    while (j < sorted.size() && sorted[j] == sorted[i]) ++j;
    const double t = static_cast<double>(j - i);
    tie_sum += t * t * t - t;
    i = j;
  }
  r.variance_u = nx * ny / 12.0 * ((n + 1) - tie_sum / (n * (n - 1)));
  if (!(r.variance_u > 0)) return r;
  const NormalApproximation a = ApproximateByNormal(r.u_x, r.mean_u, r.variance_u, continuity_correction);
  r.z = a.z;
  r.p_two_sided = a.p_two_sided;
  r.p_x_less = a.p_less;
  r.p_x_greater = a.p_greater;
  r.valid = true;
  return r;
}

}  // namespace orbed::stats
