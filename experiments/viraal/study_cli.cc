#include "experiments/viraal/study_cli.h"
#include "lcmtypes/contract/alignment_trial.h"

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "base/command_line.h"
#include "base/format.h"
#include "base/source_paths.h"
#include "base/stats.h"
#include "experiments/viraal/landmark_validation.h"
#include "experiments/viraal/paper_reference.h"
#include "experiments/viraal/rank_flip.h"
#include "experiments/viraal/study_tables.h"
#include "experiments/viraal/viraal_study.h"

namespace orbed::study {
namespace {

constexpr int kMaxTrialsInTable = 10;

// A positive decimal integer that fits an int, the whole text; else false.
bool ParsePositiveInt(const std::string& text, int* value) {
  if (text.empty() || text[0] < '0' || text[0] > '9') return false;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (errno != 0 || *end != '\0' || v < 1 || v > INT_MAX) return false;
  *value = static_cast<int>(v);
  return true;
}

// --trials' transform: refuses what ParsePositiveInt refuses and hands CLI11 the plain decimal form
// (CLI11's own integer parser would read "010" as octal and "0x10" as hex).
CLI::Validator PositiveDecimalInt() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        int value = 0;
        if (!ParsePositiveInt(text, &value)) return "needs a positive integer, got '" + text + "'";
        text = std::to_string(value);
        return "";
      },
      "POSITIVE");
}

std::string MeanStdText(const std::vector<double>& x, int digits) {
  return Fixed(stats::Mean(x), digits) + " +/- " + Fixed(stats::StdDev(x), digits);
}

// p-values as people read them: four decimals, or the power of ten when smaller.
std::string PValue(double p) {
  if (p >= 1e-4) return Fixed(p, 4);
  char text[32];
  std::snprintf(text, sizeof(text), "%.1e", p);
  return text;
}

const viraal::PaperFigure* PaperFor(const std::string& mode) {
  if (mode == "ar_reflective") return &viraal::kPaperArReflective;
  if (mode == "ar") return &viraal::kPaperAr;
  return nullptr;
}

// Per mode: the trials' errors, the SE(3) means of consecutive triples (the paper's N = 3); then
// the comparison of the first two modes.
std::string Summary(const StudyOptions& options, const viraal::RunResults& results) {
  std::string text;
  std::vector<std::vector<double>> misalignment, truth_misalignment;
  for (const viraal::SessionResult& s : results.sessions) {
    std::vector<double> mis, truth_mis, trans, rot;
    for (const viraal::TrialResult& t : s.trials) {
      mis.push_back(t.errors.misalignment_mm);
      truth_mis.push_back(t.errors.truth_misalignment_mm);
      trans.push_back(t.errors.translation_error_mm);
      rot.push_back(t.errors.rotation_error_deg);
    }
    misalignment.push_back(mis);
    truth_misalignment.push_back(truth_mis);
    const viraal::Table1Row table1 = viraal::SessionTable1Row(s);
    const auto axes = [](const Eigen::Vector3d& v) {
      return "(" + Fixed(v.x(), 1) + ", " + Fixed(v.y(), 1) + ", " + Fixed(v.z(), 1) + ")";
    };
    text += s.mode + " (" + std::to_string(s.trials.size()) + " trials)\n";
    text += "  Table 1 [mm]       " + Fixed(table1.mean_mm, 1) + " +/- " + Fixed(table1.std_mm, 1);
    if (const viraal::PaperFigure* paper = PaperFor(s.mode)) {
      text += "   (paper: " + Fixed(paper->misalignment_mm, 1) + " +/- " + Fixed(paper->std_mm, 1) + " mm)";
    }
    text += "\n    per axis x, y, z: means " + axes(table1.axes_mean_mm) + ", standard deviations " +
            axes(table1.axes_std_mm) + "\n";
    text += "  misalignment [mm]  " + MeanStdText(mis, 1) + "   (mean of the trials' ||t_bar||)\n";
    text += "  true mis. [mm]     " + MeanStdText(truth_mis, 1) +
            "   (the same from the truth's landmarks: the registration, not the user's view)\n";
    text += "  translation [mm]   " + MeanStdText(trans, 1) + "\n";
    text += "  rotation [deg]     " + MeanStdText(rot, 2) + "\n";
    std::vector<double> triples, true_triples;
    for (const GroupMean& g : GroupMeans(options, s, 3)) {
      triples.push_back(g.errors.misalignment_mm);
      true_triples.push_back(g.errors.truth_misalignment_mm);
    }
    text += "  SE(3) means of N = 3 consecutive trials (" + std::to_string(triples.size()) +
            "): misalignment " + MeanStdText(triples, 1) + " mm, from the truth's landmarks " +
            MeanStdText(true_triples, 1) + " mm\n";
  }
  if (misalignment.size() >= 2) {
    const std::string a = results.sessions[0].mode, b = results.sessions[1].mode;
    for (const auto* samples : {&misalignment, &truth_misalignment}) {
      const stats::MannWhitneyResult mw = stats::MannWhitneyU((*samples)[0], (*samples)[1]);
      text += std::string("Mann-Whitney U, trial ") + (samples == &misalignment ? "" : "true ") +
              "misalignment, one-sided (" + a + " < " + b + "): ";
      text += mw.valid
                  ? "U = " + Fixed(mw.u_x, 1) + ", z = " + Fixed(mw.z, 2) + ", p = " + PValue(mw.p_x_less)
                  : std::string("not defined for these samples");
      text += "\n";
    }
  }
  text += "paper, SE(3) mean of N = 3 trials with the display: " +
          Fixed(viraal::kPaperArReflectiveMean.misalignment_mm, 1) + " +/- " +
          Fixed(viraal::kPaperArReflectiveMean.std_mm, 2) + " mm\n";
  return text;
}

// The optical-table experiment: mean error per separation and over all, beside the paper's.
std::string LandmarkValidationSummary(const LandmarkValidationOptions& options, const LandmarkValidation& v) {
  std::string text =
      "Landmark measurement error (optical table; each target triangulated from 2 gaze rays; " +
      std::to_string(options.repeats) + " measurements per separation; pointing sigma " +
      Fixed(options.pointing_std_deg, 2) + " deg per axis)\n";
  for (double separation : options.separations_mm) {
    std::vector<double> errors;
    for (const LandmarkMeasurement& m : v.measurements) {
      if (m.separation_mm == separation) errors.push_back(m.error_mm);
    }
    char label[32];
    std::snprintf(label, sizeof(label), "  %6.0f mm apart: ", separation);
    text += label + std::string("error ") + MeanStdText(errors, 1) + " mm\n";
  }
  text += "  all " + std::to_string(v.measurements.size()) + ": average error " + Fixed(v.mean_error_mm, 1) +
          " mm   (paper: " + Fixed(kPaperLandmarkValidationMm, 1) + " mm over 12 measurements)\n";
  return text;
}

}  // namespace

int RunUserStudy(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-user-study: the ViRAAl experiment of `scripts/orbed run` without the bus: the same\n"
      "headset trials, registration and errors, for as many trials as wanted. Prints the table\n"
      "(or, past 10 trials per mode, a summary and a rank test) beside the paper's Table 1."};
  AddVersionFlag(&app);
  StudyOptions o;
  std::string scenario_path = SourceTreePath(viraal::kDefaultScenarioRelativePath);
  int trials = 0;
  std::string modes, json_path;
  bool quiet = false;
  app.add_option("--trials", trials, "Trials per display mode, at most 1000 (default: the scenario file's)")
      ->transform(PositiveDecimalInt())
      ->check(orbed::NumberIn(1, static_cast<int>(kMaxTrialsPerSession)));
  app.add_option("--modes", modes, "Comma-separated run order of ar_reflective, ar (default: the file's)");
  app.add_option("--seed", o.seed, "orbed-hmd's --seed: every trial's seeds derive from it")
      ->capture_default_str();
  app.add_option("--run-id", o.run_id,
                 "Run id; sessions are <run-id>-<mode> (the trials' seeds depend on it)")
      ->capture_default_str();
  app.add_option("--scenario", scenario_path, "Scenario YAML")->capture_default_str();
  app.add_option("--config", o.headset_config_paths,
                 "Headset config applied after the shipped ones, as orbed-hmd --config (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--urdf", o.urdf_path, "Robot URDF (default: sim/models/iiwa7.urdf)");
  app.add_option("--scene", o.scene_path, "Scene YAML (default: sim/models/scenes/trocar_or.yaml)");
  app.add_option("--json", json_path, "Write the results.json the conductor would write to this file");
  app.add_flag("--quiet", quiet, "No progress lines on stderr");
  bool landmark_validation = false;
  LandmarkValidationOptions validation;
  std::string csv_path;
  auto* validation_flag = app.add_flag(
      "--landmark-validation", landmark_validation,
      "Instead of alignment trials: the paper's check of the landmark measurement itself (distances of "
      "targets 5-20 cm apart on an optical table, each target triangulated from two gaze rays)");
  app.add_option("--repeats", validation.repeats, "--landmark-validation: measurements per separation")
      ->transform(PositiveDecimalInt())
      ->capture_default_str()
      ->needs(validation_flag);
  app.add_option("--pointing-std-deg", validation.pointing_std_deg,
                 "--landmark-validation: head-gaze pointing error per axis [deg]")
      ->check(orbed::NonNegativeNumber())
      ->capture_default_str()
      ->needs(validation_flag);
  int studies = 0, users = 4;
  std::uint64_t user_seed = 1;
  auto* studies_option =
      app.add_option("--studies", studies,
                     "Instead of one run: M studies of --users users each (the paper's 4 x 10 trials per "
                     "mode; --trials defaults to 10), seeded as `scripts/orbed study --seed S+users*m`; "
                     "writes one row per study and mode to --csv (rank_flip.h)")
          ->transform(PositiveDecimalInt())
          ->excludes(validation_flag);
  app.add_option("--users", users, "--studies: users per study")
      ->transform(PositiveDecimalInt())
      ->capture_default_str()
      ->needs(studies_option);
  auto* user_seed_option = app.add_option("--user-seed", user_seed,
                                          "The emulated person, as orbed-hmd --user-seed (with --studies: S, "
                                          "the first user's of the first study)");
  app.add_option("--csv", csv_path,
                 "--landmark-validation: write landmark_validation.csv to this file; --studies: the rows "
                 "(required)");
  std::string tables_dir;
  app.add_option(
         "--tables-dir", tables_dir,
         "--studies: also write every study's alignment_trials.csv and alignment_groups.csv rows into "
         "this folder, each row led by its study's index (the predictive bands read them)")
      ->needs(studies_option);
  if (const auto code = ParseArguments(&app, argc, argv, out, err)) return *code;
  if (!csv_path.empty() && !landmark_validation && studies == 0) {
    err << "orbed-user-study: --csv needs --landmark-validation or --studies\n";
    return 2;
  }
  if (studies > 0 && csv_path.empty()) {
    err << "orbed-user-study: --studies needs --csv FILE for its rows\n";
    return 2;
  }
  if (studies > 0) {
    try {
      RankFlipOptions rank;
      rank.study.scenario = viraal::LoadScenarioFile(scenario_path);
      viraal::ApplyOverrides(&rank.study.scenario, trials > 0 ? trials : 10, modes, {});
      rank.study.seed = o.seed;
      rank.study.urdf_path = o.urdf_path;
      rank.study.scene_path = o.scene_path;
      rank.study.headset_config_paths = o.headset_config_paths;
      rank.studies = studies;
      rank.users = users;
      rank.first_user_seed = user_seed;
      int last_tenth = -1;
      if (!quiet) {
        rank.progress = [&err, &last_tenth](int done, int total) {
          const int tenth = 10 * done / total;
          if (tenth == last_tenth) return;
          last_tenth = tenth;
          err << "orbed-user-study: " << done << "/" << total << " studies\n";
        };
      }
      std::ofstream trials_file, groups_file;
      if (!tables_dir.empty()) {
        trials_file.open(tables_dir + "/alignment_trials.csv");
        groups_file.open(tables_dir + "/alignment_groups.csv");
        if (!trials_file || !groups_file) throw std::runtime_error("cannot write into " + tables_dir);
        const int8_t method = rank.study.scenario.method;
        rank.on_study = [&](int m, const std::vector<viraal::RunResults>& results) {
          std::vector<UserRun> runs;
          for (size_t k = 0; k < results.size(); ++k)
            runs.push_back({"u" + std::to_string(k + 1), results[k]});
          trials_file << WithStudyColumn(AlignmentTrialsCsv(runs), m);
          groups_file << WithStudyColumn(AlignmentGroupsCsv(runs, method), m);
        };
      }
      const std::vector<StudyModeRow> rows = RunRankFlipStudies(rank);
      if (!tables_dir.empty() && !(trials_file.flush() && groups_file.flush()))
        throw std::runtime_error("cannot write into " + tables_dir);
      std::ofstream file(csv_path);
      file << RankFlipCsv(rows);
      if (!file) throw std::runtime_error("cannot write " + csv_path);
      out << "orbed-user-study: " << studies << " studies of " << users << " users x "
          << rank.study.scenario.trials << " trials per mode: " << rows.size() << " rows in " << csv_path
          << " (the flip fraction: python/orbed/study/rank_flip.py)\n";
    } catch (const std::exception& e) {
      err << "orbed-user-study: " << e.what() << "\n";
      return 1;
    }
    return 0;
  }
  if (*user_seed_option) o.user_seed = user_seed;
  if (landmark_validation) {
    try {
      validation.seed = o.seed;
      validation.slam = LoadShippedSlamConfig(o.headset_config_paths);
      const LandmarkValidation v = RunLandmarkValidation(validation);
      out << LandmarkValidationSummary(validation, v);
      if (!csv_path.empty()) {
        std::ofstream file(csv_path);
        file << LandmarkValidationCsv(v);
        if (!file) throw std::runtime_error("cannot write " + csv_path);
      }
    } catch (const std::exception& e) {
      err << "orbed-user-study: " << e.what() << "\n";
      return 1;
    }
    return 0;
  }
  try {
    o.scenario = viraal::LoadScenarioFile(scenario_path);
    viraal::ApplyOverrides(&o.scenario, trials, modes, {});
    int last_tenth = -1;  // outlives the study, which calls the callback
    if (!quiet) {
      o.progress = [&err, &last_tenth](int done, int total) {
        const int tenth = 10 * done / total;
        if (tenth == last_tenth) return;
        last_tenth = tenth;
        err << "orbed-user-study: " << done << "/" << total << " trials\n";
      };
    }
    const viraal::RunResults results = RunViraalStudy(o);
    if (results.sessions.empty() || results.sessions.front().trials.size() <= kMaxTrialsInTable) {
      out << viraal::ResultsTable(results);
    } else {
      out << Summary(o, results);
    }
    if (!json_path.empty()) {
      std::ofstream file(json_path);
      file << viraal::ResultsJson(results);
      if (!file) throw std::runtime_error("cannot write " + json_path);
    }
  } catch (const std::exception& e) {
    err << "orbed-user-study: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace orbed::study
