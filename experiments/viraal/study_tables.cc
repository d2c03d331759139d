#include "experiments/viraal/study_tables.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "base/command_line.h"
#include "base/format.h"
#include "base/json.h"
#include "base/run_folder.h"
#include "base/source_paths.h"
#include "experiments/viraal/paper_reference.h"
#include "experiments/viraal/protocol.h"
#include "experiments/viraal/viraal_study.h"

namespace orbed::study {
namespace {

std::string Csv(double value) {
  std::ostringstream text;
  text.precision(17);
  text << value;
  return text.str();
}

const char* kColumns =
    "user,mode,trial,t_x_mm,t_y_mm,t_z_mm,misalignment_mm,true_translation_mm,true_rotation_deg,duration_s,"
    "landmarks,true_misalignment_mm,v_x_mm,v_y_mm,v_z_mm\n";

std::string Row(const std::string& user, const std::string& mode, const std::string& trial,
                const viraal::ErrorMeasures& e, const std::string& duration_s) {
  const Eigen::Vector3d& t = e.misalignment_axes_mm;
  return user + "," + mode + "," + trial + "," + Csv(t.x()) + "," + Csv(t.y()) + "," + Csv(t.z()) + "," +
         Csv(t.norm()) + "," + Csv(e.translation_error_mm) + "," + Csv(e.rotation_error_deg) + "," +
         duration_s + "," + e.landmarks + "," + Csv(e.truth_misalignment_mm) + "," +
         (e.viewer_axes_mm ? Csv(e.viewer_axes_mm->x()) + "," + Csv(e.viewer_axes_mm->y()) + "," +
                                 Csv(e.viewer_axes_mm->z())
                           : std::string(",,")) +
         "\n";
}

void WritePaperRow(JsonWriter* json, const viraal::PaperTable1Axes& axes, const viraal::PaperFigure& norm) {
  json->BeginObject();
  const char* names[3] = {"t_x", "t_y", "t_z"};
  for (int k = 0; k < 3; ++k) json->Key(names[k]).Array(std::vector<double>{axes.mean_mm[k], axes.std_mm[k]});
  json->Key("norm").Array(std::vector<double>{norm.misalignment_mm, norm.std_mm});
  json->Key("num_trials").Int(40);
  json->EndObject();
}

std::string FirstUserId(const viraal::RunResults& r) {
  for (const viraal::SessionResult& s : r.sessions) {
    if (!s.trials.empty()) return s.trials.front().user_id;
  }
  return "";
}

}  // namespace

std::string AlignmentTrialsCsv(const std::vector<UserRun>& runs) {
  std::string csv = kColumns;
  for (const UserRun& run : runs) {
    for (const viraal::SessionResult& s : run.results.sessions) {
      for (const viraal::TrialResult& t : s.trials) {
        csv += Row(run.user, s.mode, std::to_string(t.index + 1), t.errors, Csv(t.user_duration_s));
      }
    }
  }
  return csv;
}

std::string AlignmentMeansCsv(const std::vector<UserRun>& runs) {
  std::string csv = kColumns;
  for (const UserRun& run : runs) {
    for (const viraal::SessionResult& s : run.results.sessions) {
      if (!s.mean) continue;
      double duration_s = 0;
      for (const viraal::TrialResult& t : s.trials) duration_s += t.user_duration_s;
      csv += Row(run.user, s.mode, "mean", s.mean->errors, Csv(duration_s));
    }
  }
  return csv;
}

std::string AlignmentGroupsCsv(const std::vector<UserRun>& runs, int8_t method, int group_size) {
  std::string csv =
      "user,mode,group,trials,misalignment_mm,true_translation_mm,true_rotation_deg,landmarks,"
      "true_misalignment_mm\n";
  for (const UserRun& run : runs) {
    for (const viraal::SessionResult& s : run.results.sessions) {
      for (const GroupMean& g : GroupMeans(s, group_size, run.results.landmarks, method)) {
        const viraal::ErrorMeasures& e = g.errors;
        csv += run.user + "," + s.mode + "," + std::to_string(g.first_trial / group_size + 1) + "," +
               std::to_string(g.first_trial + 1) + "-" + std::to_string(g.first_trial + g.num_trials) + "," +
               Csv(e.misalignment_mm) + "," + Csv(e.translation_error_mm) + "," + Csv(e.rotation_error_deg) +
               "," + e.landmarks + "," + Csv(e.truth_misalignment_mm) + "\n";
      }
    }
  }
  return csv;
}

std::string TablesJson(bool viraal, bool setup, const std::string& provenance) {
  JsonWriter json(2);
  json.BeginObject();
  if (!provenance.empty()) json.Key("provenance").String(provenance);
  json.Key("paper").BeginObject();
  json.Key("source").String(viraal::kPaperSource);
  if (viraal) {
    json.Key("table1").BeginObject();
    json.Key("ar_reflective");
    WritePaperRow(&json, viraal::kPaperArReflectiveAxes, viraal::kPaperArReflective);
    json.Key("ar");
    WritePaperRow(&json, viraal::kPaperArAxes, viraal::kPaperAr);
    json.Key("se3_mean").BeginObject();
    json.Key("ar_reflective").BeginObject();
    json.Key("norm").Array(std::vector<double>{viraal::kPaperArReflectiveMean.misalignment_mm,
                                               viraal::kPaperArReflectiveMean.std_mm});
    json.EndObject();
    json.EndObject();
    json.EndObject();
  }
  json.Key("landmark_validation_mm").Number(kPaperLandmarkValidationMm);
  if (setup) WriteSetupPaper(&json);
  json.EndObject();
  json.EndObject();
  return json.str() + "\n";
}

int RunStudyTables(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-study-tables: the files of the study from its runs' results.json (one run per\n"
      "user, named u1, u2, ... in the order given): alignment_trials.csv, alignment_means.csv,\n"
      "alignment_groups.csv, landmark_validation.csv, the set-up CSVs and tables.json (the paper's\n"
      "figures) in --out; python3 -m orbed.study then computes the tables.\n"
      "`scripts/orbed study` runs the users and then this."};
  AddVersionFlag(&app);
  std::string out_dir;
  std::vector<std::string> run_paths;
  LandmarkValidationOptions validation;
  std::vector<std::string> config_paths;
  app.add_option("--out", out_dir, "Folder to write the files into (created if missing)")->required();
  app.add_option("--seed", validation.seed, "Seed of the landmark check")->capture_default_str();
  std::string scenario_path = SourceTreePath(viraal::kDefaultScenarioRelativePath);
  app.add_option("--scenario", scenario_path, "The runs' scenario: its SE(3) averaging method for the groups")
      ->capture_default_str();
  app.add_option("--config", config_paths,
                 "Headset config applied over the shipped ones (the runs' --config)");
  std::vector<std::string> setup_paths;
  // One value per --setup, so that ViRAAl runs may follow.
  app.add_option("--setup", setup_paths,
                 "A set-up user's setup_results.json or its run folder (orbed-setup); one per --setup")
      ->allow_extra_args(false);
  std::vector<std::string> setup_truth_paths;
  app.add_option("--setup-truth", setup_truth_paths,
                 "The same set-up users run with orbed-setup --registration truth (the registration's share "
                 "of the error); one per --setup-truth")
      ->allow_extra_args(false);
  app.add_option("runs", run_paths, "Each ViRAAl user's results.json or its run folder");
  bool paper_only = false;
  app.add_flag(
      "--paper-only", paper_only,
      "Write only tables.json with the paper's figures of both halves (no runs; the predictive bands "
      "compare with them)");
  if (const auto code = ParseArguments(&app, argc, argv, out, err)) return *code;
  if (paper_only) {
    if (!run_paths.empty() || !setup_paths.empty() || !setup_truth_paths.empty()) {
      err << "orbed-study-tables: --paper-only takes no runs (see --help)\n";
      return 2;
    }
    try {
      std::filesystem::create_directories(out_dir);
      const std::string path = (std::filesystem::path(out_dir) / "tables.json").string();
      std::ofstream file(path);
      file << TablesJson(true, true);
      if (!file) throw std::runtime_error("cannot write " + path);
    } catch (const std::exception& e) {
      err << "orbed-study-tables: " << e.what() << "\n";
      return 1;
    }
    out << "orbed-study-tables: wrote tables.json (the paper's figures) in " << out_dir << "\n";
    return 0;
  }
  if (run_paths.empty() && setup_paths.empty()) {
    err << "orbed-study-tables: no runs: give ViRAAl runs and/or --setup runs\n";
    return 2;
  }
  try {
    std::vector<SetupUserRun> setup_runs, setup_truth_runs;
    for (const std::string& path : setup_truth_paths) {
      setup_truth_runs.push_back(ReadSetupResults(path));
      for (const SetupRow& row : setup_truth_runs.back().setups) {
        if (row.registration == "measured")
          throw std::runtime_error(path + ": a measured-registration run given as --setup-truth");
      }
    }
    if (!setup_truth_paths.empty() && setup_paths.empty())
      throw std::runtime_error("--setup-truth needs the measured runs (--setup) to compare with");
    for (const std::string& path : setup_paths) {
      setup_runs.push_back(ReadSetupResults(path));
      for (const SetupRow& row : setup_runs.back().setups) {
        if (row.registration == "truth")
          throw std::runtime_error(path + ": a --registration truth run: give it as --setup-truth");
      }
      for (size_t k = 0; k + 1 < setup_runs.size(); ++k) {
        if (setup_runs[k].user == setup_runs.back().user) {
          throw std::runtime_error(path + ": user " + EscapeText(setup_runs.back().user) + " is there twice");
        }
      }
    }
    std::vector<UserRun> runs;
    for (size_t i = 0; i < run_paths.size(); ++i) {
      UserRun run;
      run.user = "u" + std::to_string(i + 1);
      run.results = viraal::ReadResultsFile(run_paths[i]);
      if (!run.results.ok) {
        throw std::runtime_error(run_paths[i] + ": the run did not finish (" +
                                 (run.results.error.empty() ? "status partial" : run.results.error) + ")");
      }
      // One person per user: a run whose trials name the same emulated person as an earlier user's
      // (the user seed did not reach the headset) would make two users of one.
      for (const UserRun& earlier : runs) {
        const std::string a = FirstUserId(earlier.results), b = FirstUserId(run.results);
        if (!a.empty() && a == b) {
          throw std::runtime_error(run_paths[i] + ": user " + run.user + " is the same person as " +
                                   earlier.user + " ('" + EscapeText(a) + "')");
        }
      }
      // Only the protocol's modes: their names become CSV fields, JSON keys and terminal text.
      for (const viraal::SessionResult& s : run.results.sessions) {
        if (s.mode != "ar_reflective" && s.mode != "ar") {
          throw std::runtime_error(run_paths[i] + ": mode '" + EscapeText(s.mode) +
                                   "' is not one of the study's (ar_reflective, ar)");
        }
      }
      runs.push_back(std::move(run));
    }
    validation.slam = LoadShippedSlamConfig(config_paths);
    const LandmarkValidation v = RunLandmarkValidation(validation);
    std::filesystem::create_directories(out_dir);
    std::vector<std::pair<std::string, std::string>> all;
    if (!runs.empty()) {  // no ViRAAl runs: no alignment files
      all.emplace_back("alignment_trials.csv", AlignmentTrialsCsv(runs));
      all.emplace_back("alignment_means.csv", AlignmentMeansCsv(runs));
      all.emplace_back("alignment_groups.csv",
                       AlignmentGroupsCsv(runs, viraal::LoadScenarioFile(scenario_path).method));
    }
    all.emplace_back("landmark_validation.csv", LandmarkValidationCsv(v));
    all.emplace_back("tables.json",
                     TablesJson(!runs.empty(), !setup_runs.empty(), ProvenanceRecordIn(out_dir)));
    if (!setup_runs.empty()) {
      all.emplace_back("setup_joints.csv", SetupJointsCsv(setup_runs));
      all.emplace_back("setup_times.csv", SetupTimesCsv(setup_runs));
      all.emplace_back("setup_docking.csv", SetupDockingCsv(setup_runs));
    }
    if (!setup_truth_runs.empty())
      all.emplace_back("setup_truth_joints.csv", SetupJointsCsv(setup_truth_runs));
    for (const auto& [name, text] : all) {
      const std::string path = (std::filesystem::path(out_dir) / name).string();
      std::ofstream file(path);
      file << text;
      if (!file) throw std::runtime_error("cannot write " + path);
    }
    out << "orbed-study-tables: wrote";
    for (const auto& [name, text] : all) out << " " << name;
    out << " into " << out_dir << " (the tables: python3 -m orbed.study " << out_dir << ")\n";
  } catch (const std::exception& e) {
    err << "orbed-study-tables: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace orbed::study
