#include "experiments/viraal/landmark_validation.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>

#include "base/format.h"
#include "base/random.h"
#include "base/units.h"
#include "geometry/triangulation.h"
#include "hmd_emulator/annotation.h"
#include "hmd_emulator/hmd_config.h"

namespace orbed::study {
namespace {

Eigen::Vector3d Triangulate(const std::vector<Eigen::Vector3d>& origins,
                            const std::vector<Eigen::Vector3d>& directions, const char* target) {
  const geometry::TriangulationResult r = geometry::TriangulateRays(origins, directions);
  if (!r.valid)
    throw std::runtime_error(std::string("landmark validation: target ") + target + ": " + r.reason);
  return r.p_W;
}

void CheckOptions(const LandmarkValidationOptions& o) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (o.separations_mm.empty())
    throw std::invalid_argument("landmark validation: no target separation given");
  for (double s : o.separations_mm) {
    if (!positive(s) || s > 2000) {
      throw std::invalid_argument("landmark validation: separation " + Fixed(s, 1) +
                                  " mm is not in (0, 2000]");
    }
  }
  if (o.repeats < 1) throw std::invalid_argument("landmark validation: repeats must be >= 1");
  if (!std::isfinite(o.pointing_std_deg) || o.pointing_std_deg < 0) {
    throw std::invalid_argument("landmark validation: pointing_std_deg must be >= 0");
  }
  for (double v :
       {o.eye_height_m, o.standoff_m, o.baseline_m, o.dwell_s, o.walk_speed_m_per_s, o.slam.rate_hz}) {
    if (!positive(v)) throw std::invalid_argument("landmark validation: geometry and times must be > 0");
  }
  if (!std::isfinite(o.table_height_m) || o.table_height_m >= o.eye_height_m) {
    throw std::invalid_argument("landmark validation: the table top must be below the eyes");
  }
  if (!std::isfinite(o.centre_jitter_m) || o.centre_jitter_m < 0) {
    throw std::invalid_argument("landmark validation: centre_jitter_m must be >= 0");
  }
  // Every target in front of the head, never below it (where the line of sight is vertical and the
  // head's heading undefined).
  const double largest_separation_m =
      1e-3 * *std::max_element(o.separations_mm.begin(), o.separations_mm.end());
  if (o.standoff_m <= o.centre_jitter_m * std::sqrt(2.0) + 0.5 * largest_separation_m + 0.05) {
    throw std::invalid_argument(
        "landmark validation: standoff_m must exceed centre_jitter_m * sqrt(2) + half the largest "
        "separation + 0.05 m (a target would lie under the head)");
  }
}

}  // namespace

LandmarkValidation RunLandmarkValidation(const LandmarkValidationOptions& options) {
  CheckOptions(options);
  LandmarkValidation out;
  Random rng(options.seed);
  const Eigen::Vector3d p_WH1(0.0, 0.0, options.eye_height_m);
  const Eigen::Vector3d p_WH2 = p_WH1 + Eigen::Vector3d(0.0, options.baseline_m, 0.0);
  double sum_error_mm = 0;
  const hmd::AnnotationStyle style{options.pointing_std_deg, options.dwell_s, options.walk_speed_m_per_s};
  for (double separation_mm : options.separations_mm) {
    for (int repeat = 0; repeat < options.repeats; ++repeat) {
      const double cx = rng.Uniform(-options.centre_jitter_m, options.centre_jitter_m);
      const double cy = rng.Uniform(-options.centre_jitter_m, options.centre_jitter_m);
      const double heading = rng.Uniform(0.0, 2.0 * M_PI);
      const std::uint64_t person_seed = rng.NextSeed();
      const Eigen::Vector3d centre(options.standoff_m + cx, cy, options.table_height_m);
      const Eigen::Vector3d half =
          0.5e-3 * separation_mm * Eigen::Vector3d(std::cos(heading), std::sin(heading), 0);
      const Eigen::Vector3d p_WA = centre - half, p_WB = centre + half;

      hmd::SlamConfig slam = options.slam;
      slam.seed = person_seed;
      slam.faults.clear();
      hmd::SlamModel model(slam);
      hmd::AnnotatingPerson person(&model, 0.0, style, person_seed ^ 0x9e3779b97f4a7c15ULL);
      std::vector<Eigen::Vector3d> origins_A, directions_A, origins_B, directions_B;
      auto record = [&person](const Eigen::Vector3d& p_WH, const Eigen::Vector3d& p_WQ,
                              std::vector<Eigen::Vector3d>* origins,
                              std::vector<Eigen::Vector3d>* directions) {
        const hmd::GazeRayRecord ray = person.Annotate(p_WH, p_WQ);
        origins->push_back(ray.origin_W);
        directions->push_back(ray.direction_W);
      };
      record(p_WH1, p_WA, &origins_A, &directions_A);
      record(p_WH1, p_WB, &origins_B, &directions_B);
      person.Walk(p_WH1, p_WH2, centre);
      record(p_WH2, p_WA, &origins_A, &directions_A);
      record(p_WH2, p_WB, &origins_B, &directions_B);
      const Eigen::Vector3d x_A = Triangulate(origins_A, directions_A, "A");
      const Eigen::Vector3d x_B = Triangulate(origins_B, directions_B, "B");

      LandmarkMeasurement m;
      m.repeat = repeat;
      m.separation_mm = separation_mm;
      m.measured_mm = 1e3 * (x_A - x_B).norm();
      m.error_mm = std::abs(m.measured_mm - separation_mm);
      sum_error_mm += m.error_mm;
      out.measurements.push_back(m);
    }
  }
  out.mean_error_mm = sum_error_mm / static_cast<double>(out.measurements.size());
  return out;
}

std::string LandmarkValidationCsv(const LandmarkValidation& validation) {
  std::ostringstream csv;
  csv.precision(17);
  csv << "repeat,separation_mm,measured_mm,error_mm\n";
  for (const LandmarkMeasurement& m : validation.measurements) {
    csv << (m.repeat + 1) << "," << m.separation_mm << "," << m.measured_mm << "," << m.error_mm << "\n";
  }
  return csv.str();
}

hmd::SlamConfig LoadShippedSlamConfig(const std::vector<std::string>& headset_config_paths) {
  std::vector<std::string> paths;
  for (const auto& relative : hmd::DefaultHmdConfigRelativePaths())
    paths.push_back(hmd::HmdSourcePath(relative));
  paths.insert(paths.end(), headset_config_paths.begin(), headset_config_paths.end());
  return hmd::LoadHmdConfigs(paths).slam;
}

}  // namespace orbed::study
