#pragma once
/// @file
/// A small seeded random source for the emulators (SLAM, user): std::mt19937_64, whose output
/// sequence the C++ standard fixes, with uniform and normal variates computed here (not by
/// <random>'s distributions, whose algorithms are implementation-defined) so that a seed gives the
/// same person and the same walk with any standard library. With any compiler too, as long as
/// callers draw once per statement: the arguments of one call are evaluated in an unspecified order.
///
/// Threading: one Random per thread (not synchronised).

#include <cmath>
#include <cstdint>
#include <random>

#include <Eigen/Core>

namespace orbed {

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}

  /// Uniform on [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Uniform on [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }

  /// Standard normal (Marsaglia polar method; the spare variate is kept for the next call).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * Uniform() - 1.0;
      v = 2.0 * Uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double m = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * m;
    has_spare_ = true;
    return u * m;
  }
  double Normal(double mean, double stddev) { return mean + stddev * Normal(); }
  Eigen::Vector3d Normal3() {
    const double x = Normal(), y = Normal(), z = Normal();
    return Eigen::Vector3d(x, y, z);
  }
  /// Exponential with the given mean (> 0).
  double Exponential(double mean) { return -mean * std::log(1.0 - Uniform()); }
  /// Log-normal with median 1 and log-standard-deviation sigma_ln: exp(sigma_ln · N(0, 1)).
  double LogNormalUnitMedian(double sigma_ln) { return std::exp(sigma_ln * Normal()); }

  /// A seed for a child stream (e.g. one per trial) derived from this one.
  std::uint64_t NextSeed() { return engine_(); }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace orbed
