#include "experiments/viraal/rank_flip.h"

#include <limits>
#include <sstream>
#include <stdexcept>

#include "experiments/viraal/results.h"

namespace orbed::study {
namespace {

std::string Csv(double value) {
  std::ostringstream text;
  text.precision(17);
  text << value;
  return text.str();
}

}  // namespace

std::uint64_t StudyUserSeed(std::uint64_t seed, int k) { return seed + static_cast<std::uint64_t>(k) - 1; }

std::string StudyRunId(std::uint64_t seed, int k) {
  return "study-s" + std::to_string(seed) + "-u" + std::to_string(k);
}

std::vector<StudyModeRow> StudyRows(int study, std::uint64_t first_user_seed,
                                    const std::vector<viraal::RunResults>& users) {
  std::vector<StudyModeRow> rows;
  if (users.empty()) return rows;
  for (const viraal::SessionResult& first : users.front().sessions) {
    StudyModeRow row;
    row.study = study;
    row.first_user_seed = first_user_seed;
    row.mode = first.mode;
    row.users = static_cast<int>(users.size());
    std::vector<Eigen::Vector3d> axes_W, axes_S;
    bool every_viewer = true;
    for (const viraal::RunResults& user : users) {
      for (const viraal::SessionResult& s : user.sessions) {
        if (s.mode != row.mode) continue;
        for (const viraal::TrialResult& t : s.trials) {
          axes_W.push_back(t.errors.misalignment_axes_mm);
          if (t.errors.viewer_axes_mm) {
            axes_S.push_back(*t.errors.viewer_axes_mm);
          } else {
            every_viewer = false;
          }
          row.true_translation_mm += t.errors.translation_error_mm;
          row.true_misalignment_mm += t.errors.truth_misalignment_mm;
        }
      }
    }
    row.trials = static_cast<int>(axes_W.size());
    if (row.trials == 0) continue;
    row.measured_w_mm = viraal::ComputeTable1Row(axes_W).mean_mm;
    row.measured_s_mm =
        every_viewer ? viraal::ComputeTable1Row(axes_S).mean_mm : std::numeric_limits<double>::quiet_NaN();
    row.true_translation_mm /= row.trials;
    row.true_misalignment_mm /= row.trials;
    rows.push_back(row);
  }
  return rows;
}

std::vector<StudyModeRow> RunRankFlipStudies(const RankFlipOptions& options) {
  if (options.studies < 1 || options.users < 1)
    throw std::invalid_argument("rank flip: at least one study of at least one user");
  std::vector<StudyModeRow> rows;
  for (int m = 0; m < options.studies; ++m) {
    const std::uint64_t seed = options.first_user_seed + static_cast<std::uint64_t>(options.users) * m;
    std::vector<viraal::RunResults> users;
    for (int k = 1; k <= options.users; ++k) {
      StudyOptions o = options.study;
      o.user_seed = StudyUserSeed(seed, k);
      o.run_id = StudyRunId(seed, k);
      o.progress = nullptr;
      users.push_back(RunViraalStudy(o));
    }
    for (StudyModeRow& row : StudyRows(m, seed, users)) rows.push_back(std::move(row));
    if (options.on_study) options.on_study(m, users);
    if (options.progress) options.progress(m + 1, options.studies);
  }
  return rows;
}

std::string RankFlipCsv(const std::vector<StudyModeRow>& rows) {
  std::string csv =
      "study,first_user_seed,mode,users,trials,measured_w_mm,measured_s_mm,true_translation_mm,"
      "true_misalignment_mm\n";
  for (const StudyModeRow& r : rows) {
    csv += std::to_string(r.study) + "," + std::to_string(r.first_user_seed) + "," + r.mode + "," +
           std::to_string(r.users) + "," + std::to_string(r.trials) + "," + Csv(r.measured_w_mm) + "," +
           Csv(r.measured_s_mm) + "," + Csv(r.true_translation_mm) + "," + Csv(r.true_misalignment_mm) + "\n";
  }
  return csv;
}

}  // namespace orbed::study
