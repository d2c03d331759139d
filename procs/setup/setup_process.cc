#include "procs/setup/setup_process.h"

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <ostream>
#include <utility>

#include <CLI/CLI.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/misalignment_t.hpp>
#include <orbed/plan_check_reply_t.hpp>
#include <orbed/registration_t.hpp>

#include "base/json_fields.h"
#include "base/log.h"
#include "base/number_list.h"
#include "base/replace_file.h"
#include "base/run_folder.h"
#include "base/source_paths.h"
#include "lcmtypes/contract/conversions.h"
#include "runtime/flags.h"
#include "sim/guidance_messages.h"

namespace orbed::setup {

SetupProcess::SetupProcess(const CommonFlags& flags, const SetupOptions& options,
                           const std::string& urdf_path, const std::string& results_dir, std::ostream* out)
    : process_(flags), results_dir_(results_dir), out_(out) {
  conductor_ = std::make_unique<SetupConductor>(options, sim::RobotModel::LoadFile(urdf_path));
  process_.Subscribe<orbed::robot_state_t>(
      options.robot_state_channel, [this](const orbed::robot_state_t& m, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnRobotState(m, Now()));
      });
  process_.Subscribe<orbed::collision_status_t>(
      options.collision_status_channel,
      [this](const orbed::collision_status_t& m, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnCollisionStatus(m, Now()));
      });
  const scenario::ConductorOptions channels;  // the alignment's channels: the defaults
  process_.Subscribe<orbed::plan_check_reply_t>(
      channels.plan_check_reply_channel,
      [this](const orbed::plan_check_reply_t& m, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnPlanCheckReply(m, Now()));
      });
  process_.Subscribe<orbed::alignment_trial_t>(
      channels.trial_channel, [this](const orbed::alignment_trial_t& m, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnTrial(m, Now()));
      });
  process_.Subscribe<orbed::registration_t>(
      channels.registration_channel, [this](const orbed::registration_t& m, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnRegistration(m, Now()));
      });
  process_.Subscribe<orbed::landmark_t>(channels.landmark_channel,
                                        [this](const orbed::landmark_t& m, const std::string&, int64_t) {
                                          if (Started()) Apply(conductor_->OnLandmark(m, Now()));
                                        });
  process_.Subscribe<orbed::misalignment_t>(
      channels.misalignment_channel, [this](const orbed::misalignment_t& m, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnMisalignment(m, Now()));
      });
  process_.Subscribe<orbed::setup_result_t>(
      options.setup_result_channel, [this](const orbed::setup_result_t& m, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnSetupResult(m, Now()));
      });
  process_.AddTimer(
      0.01,
      [this] {
        if (Started()) Apply(conductor_->Tick(Now()));
      },
      "tick");
}

ConductorTime SetupProcess::Now() const {
  return ConductorTime{process_.ClockSeconds(), process_.ClockUtime()};
}

void SetupProcess::Start() {
  if (started_) return;
  started_ = true;
  Apply(conductor_->Start(Now()));
  Write(true);
}

bool SetupProcess::Started() {
  if (!started_ && (!process_.sim_time() || process_.sim_clock().started())) Start();
  return started_;
}

int SetupProcess::Run() {
  // On the sim clock the conductor starts with its first input after the first SIM_CLOCK, so that
  // its start and request ids are sim stamps, the same in every run of a lockstep study.
  if (!process_.sim_time()) Start();
  const int code = process_.Run();
  if (!started_) {
    ORBED_LOG(kWarn) << "stopped before the sim clock started: the conductor did not run";
    return 1;
  }
  if (!finished_) {
    Apply(conductor_->Abort("interrupted before the study's set-ups were done", Now()));
    return 1;
  }
  return conductor_->run().ok ? code : 1;
}

void SetupProcess::Apply(SetupConductor::Actions actions) {
  for (const scenario::ConductorAction& action : actions.viraal) {
    if (const auto* publication = std::get_if<scenario::Publication>(&action)) {
      std::visit([&](const auto& msg) { process_.Publish(publication->channel, msg); }, publication->message);
    } else if (const auto* line = std::get_if<scenario::ProgressLine>(&action)) {
      if (out_) *out_ << "  " << line->text << "\n" << std::flush;
    } else if (const auto* entry = std::get_if<scenario::LogEntry>(&action)) {
      orbed::Log(entry->level, entry->text);
    } else if (const auto* refusal = std::get_if<scenario::Refusal>(&action)) {
      process_.Reject(refusal->key, refusal->reason);
    }
  }
  for (const SetupPublication& p : actions.publish) {
    std::visit([&](const auto& msg) { process_.Publish(p.channel, msg); }, p.message);
  }
  for (const std::string& line : actions.progress) {
    if (out_) *out_ << line << "\n" << std::flush;
    ORBED_LOG(kInfo) << line;
  }
  for (const scenario::Refusal& r : actions.refusals) process_.Reject(r.key, r.reason);
  if (finished_) return;
  if (conductor_->done()) {
    finished_ = true;
    Write(false);
    if (conductor_->run().ok) {
      process_.RequestStop();
    } else {
      process_.Fail(conductor_->run().error);
    }
  } else if (conductor_->run().setups.size() != written_setups_) {
    Write(true);
  }
}

void SetupProcess::Write(bool partial) {
  written_setups_ = conductor_->run().setups.size();
  std::error_code ec;
  std::filesystem::create_directories(results_dir_, ec);
  const std::string path = results_dir_ + "/setup_results.json";
  SetupRun run = conductor_->run();
  run.provenance = ProvenanceRecordIn(results_dir_);
  std::string error;
  if (!ReplaceFile(path, SetupRunJson(run, partial), &error)) {
    ORBED_LOG(kWarn) << "cannot write " << path << ": " << error;
  } else if (!partial && out_) {
    *out_ << "set-up results: " << path << "\n" << std::flush;
  }
}

int RunSetup(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-setup: one user's part of the paper's robot set-up study (Sec. IV-B, Tables 2-4). For\n"
      "each mode of the user's order and each target: in the headset modes the user aligns N times\n"
      "and the mean is applied, the arm is parked at the start, and SETUP_TASK asks orbed-assistant\n"
      "to set the arm up to the target (orbed-guidance shows it). Writes setup_results.json."};
  CommonFlags common("orbed-setup");
  AddCommonFlags(&app, &common);
  AddSimTimeFlag(&app, &common);
  SetupOptions options;
  std::string plan_path, scenario_path, urdf_path, results_dir, modes, start_deg = "0,20,0,-60,0,40,0";
  uint64_t user_seed = 1;
  int targets = 3, trials = 3;
  app.add_option("--user", options.user, "The user's name in task ids and results (u1, u2, ...)")
      ->capture_default_str();
  app.add_option("--user-seed", user_seed,
                 "The user's seed: the order of the modes (unless --modes) and the draw from the design")
      ->capture_default_str();
  app.add_option("--modes", modes,
                 "The order of the modes, e.g. fixed,ar,ar_reflective (default: drawn from "
                 "--user-seed)");
  std::string design_path, scene_path;
  app.add_option(
      "--design", design_path,
      "The design catalog (default: experiments/setup/design.json): the patient and --targets (start, "
      "target) pairs drawn from --user-seed, the same for every mode. Not used with --plan or "
      "--start-deg");
  app.add_option(
      "--scene", scene_path,
      "The scene the sim loads (the launch's): fixes the patient to the catalog's patient of that scene "
      "(default: the patient drawn from --user-seed)");
  CLI::Option* plan_option =
      app.add_option("--plan", plan_path,
                     "Targets from `orbed-robot plan` instead of the design (with --start-deg; default "
                     "experiments/setup/targets.json)");
  app.add_option("--targets", targets, "How many of the plan's targets per mode")
      ->check(orbed::NumberIn(1, 20))
      ->capture_default_str();
  CLI::Option* start_option = app.add_option("--start-deg", start_deg,
                                             "Where the arm is parked before each set-up [deg], with the "
                                             "plan's targets instead of the design")
                                  ->capture_default_str();
  app.add_option("--scenario", scenario_path,
                 "The alignment protocol (default: experiments/viraal/viraal.yaml)");
  app.add_option("--trials", trials, "Alignments before each headset set-up (the paper: N = 3)")
      ->check(orbed::NumberIn(1, 100))
      ->capture_default_str();
  std::string registration = "measured";
  app.add_option("--registration", registration,
                 "Headset modes: 'measured' (N alignments, their mean; the paper) or 'truth' (the true base "
                 "pose published as the registration: the registration's share of the error)")
      ->check(CLI::IsMember({"measured", "truth"}))
      ->capture_default_str();
  app.add_option("--run-id", options.run_id, "Run id (sessions are <run-id>-<task id>-<mode>)")
      ->capture_default_str();
  app.add_option("--results-dir", results_dir,
                 "Folder of setup_results.json (default: $ORBED_LOG_DIR, else .)");
  app.add_option("--urdf", urdf_path, "Robot URDF (default: the shipped iiwa 7)");
  app.add_option("--task-timeout-s", options.task_timeout_s, "Wait for a SETUP_RESULT [s]")
      ->check(orbed::NumberIn(1.0, 36000.0))
      ->capture_default_str();
  app.add_option("--move-timeout-s", options.move_timeout_s, "Wait for the arm to reach a configuration [s]")
      ->check(orbed::NumberIn(1.0, 3600.0))
      ->capture_default_str();
  app.add_option("--request-deadline-s", options.request_deadline_s,
                 "Wait this long for the headset's and the registration server's answers while aligning, "
                 "re-sending the requests meanwhile [s]")
      ->check(FiniteNumber())
      ->check(orbed::NumberIn(1.0, 3600.0))
      ->capture_default_str();
  std::string resume;
  app.add_option("--resume", resume,
                 "Continue a run that stopped before its end: its setup_results.json (or the folder). Its "
                 "finished set-ups are kept, the rest are run");
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  try {
    options.modes = modes.empty() ? ModeOrderForSeed(user_seed) : ModeOrderFromNames(modes);
    options.start_deg = ParseNumberList(start_deg, "--start-deg");
    options.perfect_registration = registration == "truth";
  } catch (const std::invalid_argument& e) {
    err << "orbed-setup: " << e.what() << "\n";
    return 2;
  }
  try {
    if (urdf_path.empty()) urdf_path = SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath);
    if (plan_path.empty()) plan_path = SourceTreePath("experiments/setup/targets.json");
    if (scenario_path.empty()) scenario_path = SourceTreePath(viraal::kDefaultScenarioRelativePath);
    if (results_dir.empty()) {
      const char* env = std::getenv("ORBED_LOG_DIR");
      results_dir = env && *env ? env : ".";
    }
    const sim::RobotModel model = sim::RobotModel::LoadFile(urdf_path);
    if (plan_option->count() > 0 || start_option->count() > 0) {
      options.targets_deg = PlanTargetsDeg(plan_path, targets, model);
    } else {
      const UserDesign design =
          UserDesignFor(design_path.empty() ? SourceTreePath(kDefaultDesignRelativePath) : design_path,
                        scene_path, user_seed, targets);
      out << "design: patient " << design.patient << " (" << design.scene << "):";
      for (const DesignPair& p : design.pairs) {
        options.targets_deg.push_back(p.target_deg);
        options.starts_deg.push_back(p.start_deg);
        options.retract = true;
        options.retract_scene_path = scene_path.empty() ? SourceTreePath(design.scene) : scene_path;
        options.start_ids.push_back(p.start_id);
        options.target_ids.push_back(p.target_id);
        out << " " << p.start_id << " -> " << p.target_id << ";";
      }
      out << "\n";
    }
    options.alignment = viraal::LoadScenarioFile(scenario_path);
    options.alignment.trials = trials;
    if (!resume.empty()) {
      std::string status;
      const SetupRun earlier = ReadSetupRunFile(resume, &status);
      options.kept = KeptSetups(earlier, status, options);
    }
    SetupProcess setup(common, options, urdf_path, results_dir, &out);
    return setup.Run();
  } catch (const std::exception& e) {
    err << "orbed-setup: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::setup
