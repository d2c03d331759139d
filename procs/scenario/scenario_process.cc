#include "procs/scenario/scenario_process.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <ostream>
#include <stdexcept>
#include <variant>

#include "base/log.h"
#include "base/run_folder.h"
#include "base/source_paths.h"
#include "experiments/viraal/resume.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::scenario {
namespace {

std::string UtcStamp() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y%m%dT%H%M%SZ", &utc);
  return text;
}

// Fills the defaults and checks the numbers, before anything is opened.
ScenarioOptions Resolved(ScenarioOptions options, uint64_t seed) {
  if (options.urdf_path.empty())
    options.urdf_path = ScenarioSourcePath(orbed::sim::RobotModel::kDefaultUrdfRelativePath);
  if (!options.resume_path.empty()) {
    const viraal::RunResults earlier = viraal::ReadResultsFile(options.resume_path);
    if (options.conductor.run_id.empty()) options.conductor.run_id = earlier.run_id;
    options.conductor.kept_sessions =
        KeptSessions(earlier, options.conductor.run_id, seed, options.conductor.config);
    options.conductor.resumed_from = options.resume_path;
  }
  if (options.conductor.run_id.empty()) options.conductor.run_id = "viraal-" + UtcStamp();
  if (options.results_dir.empty()) {
    const char* env = std::getenv("ORBED_LOG_DIR");
    options.results_dir = env && *env ? env : ".";
  }
  options.conductor.seed = seed;
  CheckConductorOptions(options.conductor);
  if (!(options.tick_s > 0) || !std::isfinite(options.tick_s)) {
    throw std::invalid_argument("tick period must be a finite number > 0");
  }
  return options;
}

}  // namespace

std::string ScenarioSourcePath(const std::string& relative) { return orbed::SourceTreePath(relative); }

ViraalScenario::ViraalScenario(const orbed::CommonFlags& flags, const ScenarioOptions& options)
    : options_(Resolved(options, flags.seed)) {
  conductor_ = std::make_unique<ViraalConductor>(options_.conductor,
                                                 orbed::sim::RobotModel::LoadFile(options_.urdf_path));
  process_ = std::make_unique<orbed::Process>(flags);
  const ConductorOptions& o = options_.conductor;
  process_->Subscribe<orbed::robot_state_t>(
      o.robot_state_channel, [this](const orbed::robot_state_t& msg, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnRobotState(msg, Now()));
      });
  process_->Subscribe<orbed::plan_check_reply_t>(
      o.plan_check_reply_channel, [this](const orbed::plan_check_reply_t& msg, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnPlanCheckReply(msg, Now()));
      });
  process_->Subscribe<orbed::alignment_trial_t>(
      o.trial_channel, [this](const orbed::alignment_trial_t& msg, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnTrial(msg, Now()));
      });
  process_->Subscribe<orbed::registration_t>(
      o.registration_channel, [this](const orbed::registration_t& msg, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnRegistration(msg, Now()));
      });
  process_->Subscribe<orbed::landmark_t>(o.landmark_channel,
                                         [this](const orbed::landmark_t& msg, const std::string&, int64_t) {
                                           if (Started()) Apply(conductor_->OnLandmark(msg, Now()));
                                         });
  process_->Subscribe<orbed::misalignment_t>(
      o.misalignment_channel, [this](const orbed::misalignment_t& msg, const std::string&, int64_t) {
        if (Started()) Apply(conductor_->OnMisalignment(msg, Now()));
      });
  process_->AddTimer(options_.tick_s, [this] { Tick(); });
  ORBED_LOG(kInfo) << "run " << o.run_id << ": " << o.config.modes.size() << " modes x " << o.config.trials
                   << " trials, " << o.config.configurations_deg.size() << " configurations, robot "
                   << options_.urdf_path << ", results to " << options_.results_dir;
}

ViraalScenario::~ViraalScenario() = default;

bool ViraalScenario::Started() {
  if (!started_ && (!process_->sim_time() || process_->sim_clock().started())) {
    started_ = true;
    Apply(conductor_->Start(Now()));
    WriteProgress();
  }
  return started_;
}

int ViraalScenario::Run() {
  // On the sim clock the conductor starts with its first input after the first SIM_CLOCK, so that
  // its start and request ids are sim stamps, the same in every run of a lockstep study.
  if (!process_->sim_time()) Started();
  const int code = process_->Run();
  if (!started_) {
    ORBED_LOG(kWarn) << "stopped before the sim clock started: the conductor did not run";
    return 1;
  }
  if (!finished_) {
    // Stopped from outside (signal, --duration-s) before the run completed.
    Apply(conductor_->Abort("interrupted before the run completed", Now()));
    return 1;
  }
  return results_.ok ? code : 1;
}

void ViraalScenario::Tick() {
  if (Started()) Apply(conductor_->Tick(Now()));
}

ConductorTime ViraalScenario::Now() const {
  return ConductorTime{process_->ClockSeconds(), process_->ClockUtime()};
}

void ViraalScenario::Apply(const ConductorActions& actions) {
  for (const ConductorAction& action : actions) {
    if (const auto* publication = std::get_if<Publication>(&action)) {
      std::visit([&](const auto& msg) { process_->Publish(publication->channel, msg); },
                 publication->message);
    } else if (const auto* line = std::get_if<ProgressLine>(&action)) {
      Say(line->text);
    } else if (const auto* entry = std::get_if<LogEntry>(&action)) {
      orbed::Log(entry->level, entry->text);
    } else if (const auto* refusal = std::get_if<Refusal>(&action)) {
      process_->Reject(refusal->key, refusal->reason);
    }
  }
  if (conductor_->done() && !finished_) {
    Finish();
  } else if (!finished_) {
    WriteProgress();
  }
}

void ViraalScenario::WriteProgress() {
  viraal::RunResults results = conductor_->results();
  int64_t progress = 0;
  for (const viraal::SessionResult& session : results.sessions) {
    progress += static_cast<int64_t>(session.trials.size()) + (session.mean ? 1 : 0);
  }
  if (progress == progress_written_) return;
  progress_written_ = progress;
  results.partial = true;
  results.duration_s = Now().t_s;
  results.rejected_inputs = process_->rejections().total();
  results.provenance = ProvenanceRecordIn(options_.results_dir);
  try {
    std::filesystem::create_directories(options_.results_dir);
    results_path_ = viraal::WriteResultsFile(options_.results_dir, viraal::ResultsJson(results));
  } catch (const std::exception& e) {
    ORBED_LOG(kWarn) << "cannot write the results so far: " << e.what();
  }
}

void ViraalScenario::Finish() {
  finished_ = true;
  results_ = conductor_->results();
  results_.rejected_inputs = process_->rejections().total();
  results_.provenance = ProvenanceRecordIn(options_.results_dir);
  ORBED_LOG(kInfo) << conductor_->retries() << " request(s) re-sent for lack of an answer";
  try {
    std::filesystem::create_directories(options_.results_dir);
    results_path_ = viraal::WriteResultsFile(options_.results_dir, viraal::ResultsJson(results_));
  } catch (const std::exception& e) {
    if (results_.ok) {
      results_.ok = false;
      results_.error = std::string("cannot write the results: ") + e.what();
      process_->Fail(results_.error);
      return;
    }
    ORBED_LOG(kError) << "cannot write the results: " << e.what();
  }
  if (results_.ok) {
    if (options_.out) *options_.out << "\n" << viraal::ResultsTable(results_) << std::flush;
    char duration[32];
    std::snprintf(duration, sizeof(duration), "%.1f", results_.duration_s);
    Say("results: " + results_path_ + " (" + duration + " s)");
    process_->RequestStop();
  } else {
    Say("FAILED: " + results_.error);
    process_->Fail(results_.error);
  }
}

void ViraalScenario::Say(const std::string& line) {
  if (options_.out) *options_.out << line << "\n" << std::flush;
}

}  // namespace orbed::scenario
