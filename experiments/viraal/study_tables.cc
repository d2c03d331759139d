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
#include "experiments/viraal/paper_reference.h"

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
    "landmarks,true_misalignment_mm\n";

std::string Row(const std::string& user, const std::string& mode, const std::string& trial,
                const viraal::ErrorMeasures& e, const std::string& duration_s) {
  const Eigen::Vector3d& t = e.misalignment_axes_mm;
  return user + "," + mode + "," + trial + "," + Csv(t.x()) + "," + Csv(t.y()) + "," + Csv(t.z()) + "," +
         Csv(t.norm()) + "," + Csv(e.translation_error_mm) + "," + Csv(e.rotation_error_deg) + "," +
         duration_s + "," + e.landmarks + "," + Csv(e.truth_misalignment_mm) + "\n";
}

void WriteRow(JsonWriter* json, const viraal::Table1Row& row) {
  json->BeginObject();
  const char* axes[3] = {"t_x", "t_y", "t_z"};
  for (int k = 0; k < 3; ++k)
    json->Key(axes[k]).Array(std::vector<double>{row.axes_mean_mm[k], row.axes_std_mm[k]});
  json->Key("norm").Array(std::vector<double>{row.mean_mm, row.std_mm});
  json->Key("num_trials").Int(row.num_trials);
  json->EndObject();
}

void WritePaperRow(JsonWriter* json, const viraal::PaperTable1Axes& axes, const viraal::PaperFigure& norm) {
  json->BeginObject();
  const char* names[3] = {"t_x", "t_y", "t_z"};
  for (int k = 0; k < 3; ++k) json->Key(names[k]).Array(std::vector<double>{axes.mean_mm[k], axes.std_mm[k]});
  json->Key("norm").Array(std::vector<double>{norm.misalignment_mm, norm.std_mm});
  json->Key("num_trials").Int(40);
  json->EndObject();
}

const viraal::SessionResult* FindSession(const viraal::RunResults& r, const std::string& mode) {
  for (const viraal::SessionResult& s : r.sessions) {
    if (s.mode == mode) return &s;
  }
  return nullptr;
}

std::string RowText(const viraal::Table1Row& row) {
  return Fixed(row.mean_mm, 1) + " +/- " + Fixed(row.std_mm, 1) + " mm  (x, y, z means " +
         Fixed(row.axes_mean_mm.x(), 1) + ", " + Fixed(row.axes_mean_mm.y(), 1) + ", " +
         Fixed(row.axes_mean_mm.z(), 1) + "; " + std::to_string(row.num_trials) + ")";
}

std::string FirstUserId(const viraal::RunResults& r) {
  for (const viraal::SessionResult& s : r.sessions) {
    if (!s.trials.empty()) return s.trials.front().user_id;
  }
  return "";
}

}  // namespace

std::vector<std::string> StudyModes(const std::vector<UserRun>& runs) {
  std::vector<std::string> modes;
  for (const UserRun& run : runs) {
    for (const viraal::SessionResult& s : run.results.sessions) {
      if (std::find(modes.begin(), modes.end(), s.mode) == modes.end()) modes.push_back(s.mode);
    }
  }
  return modes;
}

viraal::Table1Row ModeTrialsRow(const std::vector<UserRun>& runs, const std::string& mode) {
  std::vector<Eigen::Vector3d> axes;
  for (const UserRun& run : runs) {
    if (const viraal::SessionResult* s = FindSession(run.results, mode)) {
      for (const viraal::TrialResult& t : s->trials) axes.push_back(t.errors.misalignment_axes_mm);
    }
  }
  return viraal::ComputeTable1Row(axes);
}

viraal::Table1Row ModeMeansRow(const std::vector<UserRun>& runs, const std::string& mode) {
  std::vector<Eigen::Vector3d> axes;
  for (const UserRun& run : runs) {
    const viraal::SessionResult* s = FindSession(run.results, mode);
    if (s != nullptr && s->mean) axes.push_back(s->mean->errors.misalignment_axes_mm);
  }
  return viraal::ComputeTable1Row(axes);
}

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

std::string TablesJson(const std::vector<UserRun>& runs, const LandmarkValidation& validation,
                       const std::vector<SetupUserRun>& setup_runs,
                       const std::vector<SetupUserRun>& setup_truth_runs, const std::string& provenance) {
  JsonWriter json(2);
  json.BeginObject();
  if (!provenance.empty()) json.Key("provenance").String(provenance);
  json.Key("users").Int(static_cast<int64_t>(runs.size()));
  json.Key("table1").BeginObject();
  for (const std::string& mode : StudyModes(runs)) {
    json.Key(mode);
    WriteRow(&json, ModeTrialsRow(runs, mode));
  }
  json.Key("se3_mean").BeginObject();
  for (const std::string& mode : StudyModes(runs)) {
    json.Key(mode);
    WriteRow(&json, ModeMeansRow(runs, mode));
  }
  json.EndObject();
  json.EndObject();
  json.Key("landmark_validation_mm").Number(validation.mean_error_mm);
  if (!setup_runs.empty()) WriteSetupTables(&json, setup_runs, setup_truth_runs);
  json.Key("paper").BeginObject();
  json.Key("source").String(viraal::kPaperSource);
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
  json.Key("landmark_validation_mm").Number(kPaperLandmarkValidationMm);
  if (!setup_runs.empty()) WriteSetupPaper(&json);
  json.EndObject();
  json.EndObject();
  return json.str() + "\n";
}

std::string StudySummary(const std::vector<UserRun>& runs, const LandmarkValidation& validation) {
  std::string text = "ViRAAl study: " + std::to_string(runs.size()) + " users\n";
  for (const std::string& mode : StudyModes(runs)) {
    text += "  " + mode + "\n";
    text += "    Table 1, all trials:     " + RowText(ModeTrialsRow(runs, mode));
    if (mode == "ar_reflective") text += "   paper 16.5 +/- 11.0 mm (9.00, 10.3, 9.18)";
    if (mode == "ar") text += "   paper 30.2 +/- 23.9 mm (17.4, 11.9, 21.6)";
    text += "\n    SE(3) mean of each user: " + RowText(ModeMeansRow(runs, mode));
    if (mode == "ar_reflective") text += "   paper 11.3 +/- 1.01 mm (means of N = 3 trials)";
    text += "\n";
  }
  text += "  landmark measurement error (optical table): " + Fixed(validation.mean_error_mm, 1) +
          " mm   paper " + Fixed(kPaperLandmarkValidationMm, 1) + " mm\n";
  return text;
}

int RunStudyTables(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-study-tables: the files of the ViRAAl study from its runs' results.json (one run per\n"
      "user, named u1, u2, ... in the order given): alignment_trials.csv, alignment_means.csv,\n"
      "landmark_validation.csv and tables.json in --out, and Table 1 beside the paper's.\n"
      "`scripts/orbed study` runs the users and then this."};
  AddVersionFlag(&app);
  std::string out_dir;
  std::vector<std::string> run_paths;
  LandmarkValidationOptions validation;
  std::vector<std::string> config_paths;
  app.add_option("--out", out_dir, "Folder to write the files into (created if missing)")->required();
  app.add_option("--seed", validation.seed, "Seed of the landmark check")->capture_default_str();
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
  if (const auto code = ParseArguments(&app, argc, argv, out, err)) return *code;
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
    const std::pair<const char*, std::string> files[] = {
        {"alignment_trials.csv", AlignmentTrialsCsv(runs)},
        {"alignment_means.csv", AlignmentMeansCsv(runs)},
        {"landmark_validation.csv", LandmarkValidationCsv(v)},
        {"tables.json", TablesJson(runs, v, setup_runs, setup_truth_runs, ProvenanceRecordIn(out_dir))}};
    std::vector<std::pair<std::string, std::string>> all;
    for (const auto& [name, text] : files) {
      const bool alignment = std::string(name).rfind("alignment_", 0) == 0;
      if (!alignment || !runs.empty()) all.emplace_back(name, text);  // no ViRAAl runs: no alignment files
    }
    if (!setup_runs.empty()) {
      all.emplace_back("setup_joints.csv", SetupJointsCsv(setup_runs));
      all.emplace_back("setup_times.csv", SetupTimesCsv(setup_runs));
      all.emplace_back("setup_docking.csv", SetupDockingCsv(setup_runs));
    }
    for (const auto& [name, text] : all) {
      const std::string path = (std::filesystem::path(out_dir) / name).string();
      std::ofstream file(path);
      file << text;
      if (!file) throw std::runtime_error("cannot write " + path);
    }
    if (!runs.empty()) out << StudySummary(runs, v);
    if (!setup_runs.empty()) out << SetupSummary(setup_runs, setup_truth_runs);
  } catch (const std::exception& e) {
    err << "orbed-study-tables: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace orbed::study
