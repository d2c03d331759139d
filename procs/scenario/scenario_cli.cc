#include "procs/scenario/scenario_cli.h"

#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "experiments/viraal/protocol.h"
#include "experiments/viraal/results.h"
#include "procs/scenario/scenario_process.h"
#include "runtime/flags.h"

namespace orbed::scenario {

int PrintResults(const std::string& path, std::ostream& out, std::ostream& err) {
  viraal::RunResults results;
  try {
    results = viraal::ReadResultsFile(path);
  } catch (const std::exception& e) {
    err << "orbed-scenario: " << e.what() << "\n";
    return 1;
  }
  out << viraal::ResultsTable(results);
  if (results.ok) return 0;
  if (!results.partial) return 1;
  size_t done = 0;
  for (const viraal::SessionResult& s : results.sessions) done += s.trials.size();
  out << "the run stopped before it finished (" << done << " trial(s) done)\n";
  return 3;
}

int RunScenario(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-scenario: conducts the ViRAAl experiment: per display mode N alignment trials by\n"
      "the user (orbed-hmd) at distinct robot configurations, the registration server's SE(3)\n"
      "mean, and the errors of every trial and mean against the simulator's truth."};
  orbed::CommonFlags common("orbed-scenario");
  orbed::AddCommonFlags(&app, &common);
  orbed::AddSimTimeFlag(&app, &common);
  ScenarioOptions options;
  ConductorOptions& run = options.conductor;
  std::string scenario_path;
  int trials = 0;
  std::string modes;
  std::vector<std::string> q_deg;
  app.add_option("--scenario", scenario_path,
                 "Scenario YAML (default: experiments/viraal/viraal.yaml under $ORBED_SOURCE_DIR, else under "
                 "the source tree it was built from)");
  app.add_option("--trials", trials, "Trials per mode (overrides the file's trials)")
      ->check(orbed::NumberIn(1, 1000));
  app.add_option("--modes", modes, "Comma-separated run order of ar_reflective, ar (overrides the file)");
  app.add_option("--q-deg", q_deg,
                 "A trial configuration q1,...,q7 [deg]; repeat for each (replaces the file's list)");
  app.add_option("--run-id", run.run_id,
                 "Run id; sessions are <run-id>-<mode> (default, or empty: viraal-<UTC time>)");
  app.add_option("--resume", options.resume_path,
                 "Continue the run whose results.json (or run folder) this is: its finished trials and means "
                 "are kept, the rest is run (empty: none)");
  app.add_option("--results-dir", options.results_dir,
                 "Folder of results.json (default: $ORBED_LOG_DIR, else the working directory)");
  app.add_option("--urdf", options.urdf_path,
                 "Robot URDF for the landmark FK (default: sim/models/iiwa7.urdf)");
  app.add_option("--tolerance-deg", run.tolerance_deg, "Arrival tolerance per joint [deg]")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--startup-timeout-s", run.startup_timeout_s, "Wait for the first ROBOT_STATE [s]")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--request-deadline-s", run.request_deadline_s,
                 "Wait this long for the answer to any request (PLAN_CHECK_REPLY, ALIGNMENT_TRIAL, "
                 "REGISTRATION, LANDMARK, MISALIGNMENT), re-sending it meanwhile [s]")
      ->check(FiniteNumber())
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--move-timeout-s", run.move_timeout_s, "Wait for the arm to reach a configuration [s]")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--retry-initial-s", run.retry_initial_s,
                 "Re-send an unanswered request after this long, then after doubling intervals [s]")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--retry-max-s", run.retry_max_s, "Longest interval between re-sends of a request [s]")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  std::string headset, arm;
  AddInstanceFlag(
      &app, "--headset", &headset,
      "Conduct the ViRAAl run of headset NAME (one of several): the session's channels get the suffix "
      "_NAME (SESSION_CONTROL_H1, ALIGNMENT_TRIAL_H1, REGISTRATION_H1, LANDMARK*_H1, MISALIGNMENT*_H1)");
  AddInstanceFlag(
      &app, "--arm", &arm,
      "With the arm NAME (one of several): ROBOT_STATE, IIWA_COMMAND and PLAN_CHECK_* get the suffix "
      "_NAME");
  app.add_option("--robot-state-channel", run.robot_state_channel)->capture_default_str();
  app.add_option("--iiwa-command-channel", run.iiwa_command_channel)->capture_default_str();
  app.add_option("--plan-check-request-channel", run.plan_check_request_channel)->capture_default_str();
  app.add_option("--plan-check-reply-channel", run.plan_check_reply_channel)->capture_default_str();
  app.add_option("--session-control-channel", run.session_control_channel)->capture_default_str();
  app.add_option("--trial-channel", run.trial_channel)->capture_default_str();
  app.add_option("--registration-channel", run.registration_channel)->capture_default_str();
  app.add_option("--landmark-request-channel", run.landmark_request_channel)->capture_default_str();
  app.add_option("--landmark-channel", run.landmark_channel)->capture_default_str();
  app.add_option("--misalignment-request-channel", run.misalignment_request_channel)->capture_default_str();
  app.add_option("--misalignment-channel", run.misalignment_channel)->capture_default_str();
  std::string print_path;
  app.add_option("--print", print_path,
                 "Print the results table of a finished run (its results.json or its folder) and exit: 0 ok, "
                 "1 failed, 3 stopped before the end (it can be resumed)");
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  if (!print_path.empty()) return PrintResults(print_path, out, err);
  UseInstanceChannels(&run, headset, arm);
  common.sim_clock_arm = arm;
  try {
    if (scenario_path.empty()) scenario_path = ScenarioSourcePath(viraal::kDefaultScenarioRelativePath);
    run.config = viraal::LoadScenarioFile(scenario_path);
    viraal::ApplyOverrides(&run.config, trials, modes, q_deg);
    options.out = &out;
    ViraalScenario scenario(common, options);
    return scenario.Run();
  } catch (const std::exception& e) {
    err << "orbed-scenario: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::scenario
