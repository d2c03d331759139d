#pragma once
/// @file
/// Small statistics the processes need at run time: mean, median, quantiles, sample standard
/// deviation (geometry/, tests/load/), and the Mann–Whitney U (Wilcoxon rank-sum) test that
/// orbed-user-study prints for its trials. The study's analysis (Tables 1-4, paired tests, mixed
/// models, power) is Python's: python/orbed/study on scipy and statsmodels.
///
/// Mann–Whitney U for samples x (n_x) and y (n_y): all values are ranked together, ties getting the
/// average of the ranks they span; U_x = R_x − n_x(n_x + 1)/2 with R_x the sum of x's ranks, which
/// equals the number of pairs (x_i, y_j) with x_i > y_j plus half the tied pairs; U_y = n_x n_y − U_x.
/// Normal approximation: mean n_x n_y / 2, variance with the tie correction
///     σ² = n_x n_y / 12 · [(n + 1) − Σ_k (t_k³ − t_k) / (n (n − 1))],   n = n_x + n_y,
/// t_k the size of the k-th group of tied values; z = (U_x − mean ∓ 0.5) / σ with a continuity
/// correction of 0.5 toward the mean (optional). p-values from the standard normal:
///     two-sided:  P(|Z| ≥ |z|) (capped at 1),
///     x_less:     alternative "x tends to be smaller than y" = Φ((U_x − mean + c) / σ),
///     x_greater:  alternative "x tends to be larger than y"  = 1 − Φ((U_x − mean − c) / σ),
/// c = 0.5 with the continuity correction, else 0. Adequate for n_x, n_y ≳ 8 (the uses here have
/// hundreds); for tiny samples exact tables are better.
///
/// Threading: pure functions, reentrant.

#include <vector>

namespace orbed::stats {

/// Arithmetic mean; NaN for an empty sample.
double Mean(const std::vector<double>& x);
/// Median (the mean of the two middle values for an even count); NaN for an empty sample.
double Median(std::vector<double> x);
/// Sample standard deviation (N − 1 in the denominator); 0 for one value, NaN for none.
double StdDev(const std::vector<double>& x);
/// The q-quantile, q in [0, 1], linear interpolation between order statistics (R type 7).
double Quantile(std::vector<double> x, double q);

/// Average ranks (1-based) of x, ties sharing the mean of their ranks.
std::vector<double> AverageRanks(const std::vector<double>& x);

struct MannWhitneyResult {
  bool valid = false;  ///< false when a sample is empty or σ = 0 (all values tied)
  int n_x = 0, n_y = 0;
  double rank_sum_x = 0;    ///< R_x
  double u_x = 0, u_y = 0;  ///< U_x + U_y = n_x n_y
  double mean_u = 0;        ///< n_x n_y / 2
  double variance_u = 0;    ///< tie-corrected σ²
  double z = 0;             ///< (U_x − mean, continuity-corrected toward 0) / σ
  double p_two_sided = 1;
  double p_x_less = 1;     ///< one-sided: x stochastically smaller than y
  double p_x_greater = 1;  ///< one-sided: x stochastically larger than y
};

MannWhitneyResult MannWhitneyU(const std::vector<double>& x, const std::vector<double>& y,
                               bool continuity_correction = true);

/// Standard normal CDF Φ(z).
double NormalCdf(double z);

}  // namespace orbed::stats
