#include "experiments/setup/setup_study_cli.h"

#include <atomic>
#include <chrono>
#include <exception>
#include <filesystem>
#include <mutex>
#include <sstream>
#include <thread>

#include <CLI/CLI.hpp>
#include <orbed/guidance_t.hpp>

#include "base/command_line.h"
#include "base/format.h"
#include "base/log.h"
#include "base/replace_file.h"
#include "experiments/setup/setup_tables.h"
#include "sim/guidance_messages.h"

namespace orbed::setup {
study::SetupUserRun TableRun(const SetupRun& run) {
  study::SetupUserRun out;
  out.user = run.user;
  out.order = run.order;
  for (const SetupRecord& r : run.setups) {
    study::SetupRow row;
    row.mode = guidance::GuidanceModeName(r.mode);
    row.order = r.order;
    row.target = r.target;
    row.start_id = r.start_id;
    row.target_id = r.target_id;
    row.start_deg = r.start_deg;
    row.target_deg = r.target_deg;
    row.reached_deg = r.reached_deg;
    row.twisting = r.twisting;
    row.execution_s = r.execution_s;
    row.alignment_s = r.alignment_s;
    if (r.mode != orbed::guidance_t::MODE_FIXED_DISPLAY)
      row.registration = r.perfect_registration ? "truth" : "measured";
    row.docking_tip_mm = r.docking_tip_mm;
    row.docking_axis_deg = r.docking_axis_deg;
    row.min_clearance_m = r.min_clearance_m;
    row.contact = r.contact;
    row.collision_stops = r.collision_stops;
    out.setups.push_back(std::move(row));
  }
  return out;
}

namespace {

// The CSVs of every study, each line after the header with "<study>," first when there are several.
std::string StudyCsv(const std::vector<std::vector<study::SetupUserRun>>& studies,
                     std::string (*writer)(const std::vector<study::SetupUserRun>&)) {
  if (studies.size() == 1) return writer(studies[0]);
  std::string out;
  for (size_t m = 0; m < studies.size(); ++m) out += WithStudyColumn(writer(studies[m]), static_cast<int>(m));
  return out;
}

}  // namespace

SetupUserOptions StudyUser(const SetupUserOptions& base, uint64_t seed, const std::string& run_id, int users,
                           int study, int k) {
  SetupUserOptions o = base;
  o.user = "u" + std::to_string(k);
  o.user_seed =
      seed + static_cast<uint64_t>(study) * static_cast<uint64_t>(users) + static_cast<uint64_t>(k - 1);
  o.run_id = run_id + (study == 0 ? "" : "-m" + std::to_string(study)) + "-setup-u" + std::to_string(k);
  return o;
}

std::vector<SetupRun> RunSetupUsers(const std::vector<SetupUserOptions>& jobs, int threads,
                                    const std::function<void(int, int)>& progress) {
  std::vector<SetupRun> runs(jobs.size());
  std::vector<std::exception_ptr> errors(jobs.size());
  std::atomic<size_t> next{0};
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  auto work = [&] {
    for (size_t i = next++; i < jobs.size(); i = next++) {
      try {
        runs[i] = RunSetupUser(jobs[i]);
      } catch (...) {
        errors[i] = std::current_exception();
      }
      const int finished = ++done;
      if (progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        progress(finished, static_cast<int>(jobs.size()));
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  return runs;
}

int RunSetupStudy(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-setup-study: the robot set-up study (paper Sec. IV-B) without the bus: each user's\n"
      "launch of scripts/launch/setup.yaml done in one process by the same cores in lockstep order\n"
      "(equal to the bus run), many users and studies on threads; writes setup_joints.csv,\n"
      "setup_times.csv and setup_docking.csv (a leading `study` column for --studies > 1)."};
  AddVersionFlag(&app);
  int users = 8, studies = 1, threads = 2, targets = 3, trials = 3;
  uint64_t seed = 1;
  std::string run_id, out_dir = ".", json_dir, registration = "measured", direction, assistant_config;
  double offset_mm = 0, tilt_deg = 0;
  std::vector<double> axis;
  bool quiet = false, allow_failures = false;
  app.add_option("--users", users, "Users per study")->check(NumberIn(1, 10000))->capture_default_str();
  app.add_option("--studies", studies, "Studies (study m uses seeds S + m*U ...)")
      ->check(NumberIn(1, 100000))
      ->capture_default_str();
  app.add_option("--seed", seed, "The first user's seed")->check(NumberIn(0, 1e15))->capture_default_str();
  app.add_option("--run-id", run_id, "Run ids <ID>-setup-u<k> (default study-s<S>, as scripts/orbed study)");
  app.add_option("--targets", targets,
                 "K, the (start, target) pairs per mode each user draws from the design (or the plan's "
                 "first K targets with --plan); 1..6, as scripts/orbed study")
      ->check(NumberIn(1, 6))
      ->capture_default_str();
  std::string design_path, plan_path;
  std::vector<double> start_deg;
  app.add_option("--design", design_path,
                 "The design catalog each user draws their patient and pairs from (default "
                 "experiments/setup/design.json)");
  CLI::Option* plan_option =
      app.add_option("--plan", plan_path,
                     "Instead of the design: the targets of this `orbed-robot plan` file (e.g. "
                     "experiments/setup/targets.json), each from --start-deg, in trocar_or.yaml (orbed-setup "
                     "--plan)");
  CLI::Option* start_option =
      AddNumberListOption(&app, "--start-deg", &start_deg, 7,
                          "With --plan: where the arm is parked before each set-up [deg] (default "
                          "0,20,0,-60,0,40,0)");
  app.add_option("--trials", trials, "Alignments before each headset set-up (the paper: N = 3)")
      ->check(NumberIn(1, 100))
      ->capture_default_str();
  app.add_option("--threads", threads, "Users run at a time")->check(NumberIn(1, 256))->capture_default_str();
  app.add_option("--out", out_dir, "Folder of the CSVs")->capture_default_str();
  app.add_option("--json-dir", json_dir, "Also each user's setup_results.json under this folder");
  app.add_option("--registration", registration,
                 "Headset modes: 'measured' (N alignments, their mean) or 'truth' (the true registration)")
      ->check(CLI::IsMember({"measured", "truth"}))
      ->capture_default_str();
  app.add_option("--registration-offset-mm", offset_mm,
                 "Move every registration the assistant receives by this along the direction [mm]")
      ->check(NumberIn(-1000, 1000))
      ->capture_default_str();
  app.add_option("--registration-tilt-deg", tilt_deg,
                 "Turn every registration the assistant receives by this about the axis [deg]")
      ->check(NumberIn(-180, 180))
      ->capture_default_str();
  app.add_option("--registration-direction", direction,
                 "The offset's direction in W, X,Y,Z (default 1,0,0), or 'random' (per set-up, with a "
                 "random horizontal tilt axis)");
  AddNumberListOption(&app, "--registration-axis", &axis, 3, "The tilt's axis in W, X,Y,Z (default 0,1,0)");
  app.add_option("--assistant-config", assistant_config,
                 "The assistant's parameters (orbed-assistant --config)");
  app.add_flag("--quiet", quiet, "No progress on stderr");
  app.add_flag("--allow-failures", allow_failures,
               "A user whose run failed (e.g. the arm stopped before a collision on its way to the start) is "
               "left out of the CSVs and listed in failed_users.csv, instead of failing the study");
  if (const auto code = ParseArguments(&app, argc, argv, out, err)) return *code;

  SetupUserOptions base;
  base.targets = targets;
  base.design_path = design_path;
  base.use_plan = plan_option->count() > 0 || start_option->count() > 0;
  base.plan_path = plan_path;
  if (!start_deg.empty()) base.start_deg = start_deg;
  base.trials = trials;
  base.perfect_registration = registration == "truth";
  base.assistant_config_path = assistant_config;
  base.injection.offset_m = offset_mm * 1e-3;
  base.injection.tilt_rad = tilt_deg * M_PI / 180.0;
  auto unit = [&](const std::vector<double>& v, const char* flag, Eigen::Vector3d* u) {
    const Eigen::Vector3d x(v[0], v[1], v[2]);
    if (!(x.norm() > 1e-9)) {
      err << "orbed-setup-study: " << flag << " must not be the zero vector (see --help)\n";
      return false;
    }
    *u = x.normalized();
    return true;
  };
  if (direction == "random") {
    base.injection.random_direction = true;
  } else if (!direction.empty()) {
    std::vector<double> d;
    std::istringstream parts(direction);
    std::string part;
    while (std::getline(parts, part, ',')) {
      try {
        size_t used = 0;
        d.push_back(std::stod(part, &used));
        if (used != part.size() || !std::isfinite(d.back())) d.clear();
      } catch (const std::exception&) {
        d.clear();
      }
      if (d.empty()) break;
    }
    if (d.size() != 3) {
      err << "orbed-setup-study: --registration-direction needs X,Y,Z or 'random', got '" << direction
          << "' (see --help)\n";
      return kExitUsage;
    }
    if (!unit(d, "--registration-direction", &base.injection.direction_W)) return kExitUsage;
  }
  if (!axis.empty() && !unit(axis, "--registration-axis", &base.injection.tilt_axis_W)) return kExitUsage;
  if (run_id.empty()) run_id = "study-s" + std::to_string(seed);
  if (GetLogLevel() < LogLevel::kWarn) SetLogLevel(LogLevel::kWarn);  // the cores' lines per trial

  std::vector<SetupUserOptions> jobs;
  for (int m = 0; m < studies; ++m)
    for (int k = 1; k <= users; ++k) jobs.push_back(StudyUser(base, seed, run_id, users, m, k));
  const auto start = std::chrono::steady_clock::now();
  int shown_s = -1;
  auto progress = [&](int done, int total) {
    if (quiet) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (done < total && static_cast<int>(s) == shown_s) return;
    shown_s = static_cast<int>(s);
    err << "setup-study: " << done << "/" << total << " users, " << Fixed(s, 0) << " s elapsed"
        << (done < total ? ", about " + Fixed(s / done * (total - done), 0) + " s left" : ", done") << "\n";
  };
  std::vector<SetupRun> runs;
  try {
    runs = RunSetupUsers(jobs, threads, progress);
  } catch (const std::exception& e) {
    err << "orbed-setup-study: " << e.what() << "\n";
    return 1;
  }
  std::vector<std::vector<study::SetupUserRun>> tables(studies);
  std::string failed = "study,user,user_seed,run_id,error\n";
  int failures = 0;
  for (size_t i = 0; i < runs.size(); ++i) {
    if (!runs[i].ok) {
      if (!allow_failures || !quiet) {
        err << "orbed-setup-study: " << runs[i].run_id << " (seed " << jobs[i].user_seed
            << ") failed: " << runs[i].error << "\n";
      }
      if (!allow_failures) return 1;
      ++failures;
      std::string reason = runs[i].error;
      for (char& c : reason)
        if (c == ',' || c == '"' || c == '\n') c = ';';
      failed += std::to_string(i / users) + "," + runs[i].user + "," + std::to_string(jobs[i].user_seed) +
                "," + runs[i].run_id + "," + reason + "\n";
      continue;
    }
    tables[i / users].push_back(TableRun(runs[i]));
  }
  std::string error;
  auto write = [&](const std::string& path, const std::string& text) {
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
    if (ReplaceFile(path, text, &error)) return true;
    err << "orbed-setup-study: cannot write " << path << ": " << error << "\n";
    return false;
  };
  if (!write(out_dir + "/setup_joints.csv", StudyCsv(tables, study::SetupJointsCsv)) ||
      !write(out_dir + "/setup_times.csv", StudyCsv(tables, study::SetupTimesCsv)) ||
      !write(out_dir + "/setup_docking.csv", StudyCsv(tables, study::SetupDockingCsv)))
    return 1;
  if (allow_failures && !write(out_dir + "/failed_users.csv", failed)) return 1;
  if (!json_dir.empty()) {
    for (size_t i = 0; i < runs.size(); ++i) {
      const std::string folder =
          json_dir + (studies > 1 ? "/m" + std::to_string(i / users) : "") + "/setup-" + runs[i].user;
      if (!write(folder + "/setup_results.json", SetupRunJson(runs[i], false))) return 1;
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out << "orbed-setup-study: " << studies << " stud" << (studies == 1 ? "y" : "ies") << " of " << users
      << " users (" << runs.size() << " users, " << runs.size() * static_cast<size_t>(3 * targets)
      << " set-ups) in " << Fixed(s, 1) << " s on " << threads << " thread(s)"
      << (failures > 0 ? ", " + std::to_string(failures) + " user(s) failed (failed_users.csv)" : "")
      << "; files in " << out_dir << "\n";
  return 0;
}

}  // namespace orbed::setup
