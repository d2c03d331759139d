/// @file
/// hmd-user-study: runs the emulated ViRAAl study (user_study.h) and prints, per display mode, the
/// error statistics next to the paper's Table 1, and the Mann–Whitney comparison of the modes.
/// No LCM. Usage: hmd-user-study [--trials N] [--source DIR]  (DIR defaults to $ORBED_SOURCE_DIR or .)
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

#include "hmd_emulator/stats.h"
#include "hmd_emulator/user_study.h"
#include "procs/registration_server/se3_mean.h"
#include "sim/scene.h"

namespace {

void Print(const char* label, const std::vector<double>& v, double scale) {
  std::vector<double> s;
  for (double x : v) s.push_back(x * scale);
  std::printf("  %-34s mean %7.2f  std %7.2f  median %7.2f  p90 %7.2f\n", label, orbed::hmd::stats::Mean(s),
              orbed::hmd::stats::StdDev(s), orbed::hmd::stats::Median(s), orbed::hmd::stats::Quantile(s, 0.9));
}

}  // namespace

int main(int argc, char** argv) {
  orbed::hmd::StudyOptions o;
  const char* env = std::getenv("ORBED_SOURCE_DIR");
  if (env) o.source_dir = env;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::printf("usage: hmd-user-study [--trials N] [--source DIR] [--user FILE] [--slam FILE]\n");
      return 0;
    } else if (a == "--trials" && i + 1 < argc) {
      o.trials_per_mode = std::atoi(argv[++i]);
    } else if (a == "--source" && i + 1 < argc) {
      o.source_dir = argv[++i];
    } else if (a == "--user" && i + 1 < argc) {
      o.user_config_path = argv[++i];
    } else if (a == "--slam" && i + 1 < argc) {
      o.slam_config_path = argv[++i];
    } else {
      std::fprintf(stderr, "hmd-user-study: unknown argument '%s' (try --help)\n", a.c_str());
      return 2;
    }
  }
  try {
    const auto modes = orbed::hmd::RunStudy(o);
    // The real base (the same in every trial: one scene).
    const Eigen::Vector3d p_WR_truth =
        orbed::sim::LoadSceneFile(o.source_dir + "/" + orbed::sim::kDefaultSceneRelativePath).X_WR.translation();
    std::vector<std::vector<double>> reg;
    for (const auto& m : modes) {
      std::vector<double> t, base, rot, aug, along, lat, aug_pts, nudges, dur;
      for (const auto& tr : m.trials) {
        t.push_back(tr.registration.translation_error_m);
        base.push_back(tr.registration.base_translation_error_m);
        rot.push_back(tr.registration.rotation_error_deg);
        aug.push_back(tr.augmentation.translation_error_m);
        along.push_back(tr.augmentation.along_ray_m);
        lat.push_back(tr.augmentation.lateral_m);
        aug_pts.push_back(tr.augmentation.mean_point_error_m);
        nudges.push_back(tr.alignment.nudges);
        dur.push_back(tr.alignment.duration_s);
      }
      reg.push_back(t);
      // The paper's SE(3) averaging (registration_lib, Karcher mean, translation about the model
      // centroid) over consecutive triples of trials (three configurations, mostly one person).
      std::vector<double> mean_err;
      for (std::size_t g = 0; g + 3 <= m.trials.size(); g += 3) {
        std::vector<Eigen::Quaterniond> q;
        std::vector<Eigen::Vector3d> p;
        for (std::size_t k = g; k < g + 3; ++k) {
          q.emplace_back(m.trials[k].alignment.X_WV.linear());
          p.push_back(m.trials[k].alignment.X_WV.translation());
        }
        orbed::registration::Se3MeanOptions opt;
        // Base origin averaging (eq. 3); rotation errors are ~0.1 deg, so the centroid matters little.
        const auto r = orbed::registration::ComputeSe3Mean(q, p, opt);
        if (!r.valid) continue;
        mean_err.push_back((r.p_WV_mean - p_WR_truth).norm());
      }
      std::printf("%s (%zu trials)\n", m.name.c_str(), m.trials.size());
      Print("registration, centroid [mm]", t, 1e3);
      Print("registration, base origin [mm]", base, 1e3);
      Print("registration, rotation [deg]", rot, 1.0);
      Print("augmentation, centroid [mm]", aug, 1e3);
      Print("augmentation, along the ray [mm]", along, 1e3);
      Print("augmentation, across the ray [mm]", lat, 1e3);
      Print("augmentation, mean point [mm]", aug_pts, 1e3);
      Print("nudges", nudges, 1.0);
      Print("duration [s]", dur, 1.0);
      Print("SE(3) mean of 3, base origin [mm]", mean_err, 1e3);
    }
    if (reg.size() == 2) {
      const auto mw = orbed::hmd::stats::MannWhitneyU(reg[1], reg[0]);
      std::printf("Mann-Whitney (registration error, reflective < ar): U = %.1f, z = %.2f, p = %.3g\n", mw.u_x, mw.z,
                  mw.p_x_less);
    }
    std::printf("paper Table 1: ar 30.2 +- 23.9 mm, ar_reflective 16.5 +- 11.0 mm, SE(3) mean 11.3 mm\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hmd-user-study: %s\n", e.what());
    return 1;
  }
  return 0;
}
