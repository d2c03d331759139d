/// @file
/// Rotation averaging cost: the Karcher (geodesic L2) mean, started from the chordal mean, beside
/// the chordal (quaternion-eigenvector) mean alone, for N = 3, 10, 100, 1000 rotations in the same
/// run; the ratio Karcher / chordal is printed after the table (a ratio against a
/// baseline measured in the same run). Also the robust pipeline (L1 median + MAD rejection +
/// Karcher) for reference.
///
/// Data: a fixed-seed cluster of R_WV_i = R_c·exp(δ_i), δ_i ~ N(0, (5°)²/3 per axis) (≈ 5° RMS
/// angle, a realistic spread of user alignment trials), around a fixed centre R_c.
/// Goal: Karcher N = 3 ≤ 1.5 µs, N = 1000 ≤ 150 µs.

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "base/units.h"
#include "geometry/robust.h"
#include "geometry/rotation_mean.h"
#include "geometry/so3.h"

namespace orbed::geometry {
namespace {

std::vector<Eigen::Quaterniond> Cluster(int n) {
  std::mt19937 rng(42);
  std::normal_distribution<double> normal(0.0, 5.0 * kDegToRad / std::sqrt(3.0));
  const Eigen::Quaterniond center(Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, -0.7, 0.4).normalized()));
  std::vector<Eigen::Quaterniond> q;
  q.reserve(n);
  for (int i = 0; i < n; ++i)
    q.push_back(center * geometry::ExpQuaternion(Eigen::Vector3d(normal(rng), normal(rng), normal(rng))));
  return q;
}

void BM_ChordalMean(benchmark::State& state) {
  const std::vector<Eigen::Quaterniond> q = Cluster(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    geometry::ChordalMeanResult r = geometry::ComputeChordalMean(q);
    benchmark::DoNotOptimize(r);
  }
}

void BM_KarcherMean(benchmark::State& state) {
  const std::vector<Eigen::Quaterniond> q = Cluster(static_cast<int>(state.range(0)));
  int iterations = 0;
  for (auto _ : state) {
    geometry::KarcherMeanResult r = geometry::ComputeKarcherMean(q);
    iterations = r.iterations;
    benchmark::DoNotOptimize(r);
  }
  state.counters["karcher_iterations"] = iterations;
}

void BM_RobustRejection(benchmark::State& state) {
  const std::vector<Eigen::Quaterniond> q = Cluster(static_cast<int>(state.range(0)));
  const std::vector<Eigen::Vector3d> p(q.size(), Eigen::Vector3d(1, 2, 3));
  for (auto _ : state) {
    geometry::OutlierResult r = geometry::RejectOutliers(q, p);
    benchmark::DoNotOptimize(r);
  }
}

BENCHMARK(BM_ChordalMean)->Arg(3)->Arg(10)->Arg(100)->Arg(1000);
BENCHMARK(BM_KarcherMean)->Arg(3)->Arg(10)->Arg(100)->Arg(1000);
BENCHMARK(BM_RobustRejection)->Arg(3)->Arg(10)->Arg(100)->Arg(1000);

// The console table, then Karcher / chordal per N from the same run.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  explicit RatioReporter(OutputOptions options) : ConsoleReporter(options) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred || run.run_type != Run::RT_Iteration) continue;
      times_[run.run_name.function_name][std::stoll(run.run_name.args)] = run.GetAdjustedRealTime();
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    const auto& chordal = times_["BM_ChordalMean"];
    const auto& karcher = times_["BM_KarcherMean"];
    if (chordal.empty() || karcher.empty()) return;
    std::printf("\nKarcher (from the chordal start) / chordal, same run [%s]:\n%8s %14s %14s %8s\n",
                "real time per call, ns", "N", "chordal", "karcher", "ratio");
    for (const auto& [args, karcher_time] : karcher) {
      const auto it = chordal.find(args);
      if (it == chordal.end() || it->second <= 0.0) continue;
      std::printf("%8lld %14.4g %14.4g %8.2f\n", args, it->second, karcher_time, karcher_time / it->second);
    }
  }

 private:
  std::map<std::string, std::map<long long, double>> times_;  // [function][N] → time
};

}  // namespace
}  // namespace orbed::geometry

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // Colour only on a terminal (ConsoleReporter itself ignores --benchmark_color when given to us).
  orbed::geometry::RatioReporter reporter(isatty(fileno(stdout)) ? benchmark::ConsoleReporter::OO_ColorTabular
                                                                 : benchmark::ConsoleReporter::OO_Tabular);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
