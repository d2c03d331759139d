/// @file
/// orbed-scenario: runs the paper's ViRAAl experiment (Sec. III-B, Table 1) over the bus and exits:
/// 0 when every session finished, 1 with a one-line reason otherwise (see viraal_scenario.h).
/// Subscribes: ROBOT_STATE, PLAN_CHECK_REPLY, ALIGNMENT_TRIAL, REGISTRATION, MISALIGNMENT.
/// Publishes:  PLAN_CHECK_REQUEST, SESSION_CONTROL (START / REQUEST_TRIAL / COMPUTE / STOP),
///             IIWA_COMMAND, MISALIGNMENT_REQUEST, PROCESS_STATUS (1 Hz).
/// Writes results.json to --results-dir (default $ORBED_LOG_DIR, else the working directory) and
/// prints a progress line per step and a table at the end on stdout.
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "procs/scenario/viraal_scenario.h"

int main(int argc, char** argv) {
  CLI::App app{
      "orbed-scenario: conducts the ViRAAl experiment: per display mode N alignment trials by\n"
      "the user (orbed-hmd) at distinct robot configurations, the registration server's SE(3)\n"
      "mean, and the errors of every trial and mean against the simulator's truth."};
  orbed::CommonFlags common("orbed-scenario");
  orbed::AddCommonFlags(&app, &common);
  orbed::scenario::ScenarioOptions options;
  std::string scenario_path;
  int trials = 0;
  std::string modes;
  std::vector<std::string> q_deg;
  app.add_option("--scenario", scenario_path,
                 "Scenario YAML (default: viraal/viraal.yaml under $ORBED_SOURCE_DIR, else under "
                 "the source tree it was built from)");
  app.add_option("--trials", trials, "Trials per mode (overrides the file's trials)")
      ->check(CLI::Range(1, 1000));
  app.add_option("--modes", modes, "Comma-separated run order of ar_reflective, ar (overrides the file)");
  app.add_option("--q-deg", q_deg,
                 "A trial configuration q1,...,q7 [deg]; repeat for each (replaces the file's list)");
  app.add_option("--run-id", options.run_id,
                 "Run id; sessions are <run-id>-<mode> (default $ORBED_RUN_ID, else viraal-<UTC time>)");
  app.add_option("--results-dir", options.results_dir,
                 "Folder of results.json (default: $ORBED_LOG_DIR, else the working directory)");
  app.add_option("--urdf", options.urdf_path,
                 "Robot URDF for the landmark FK (default: sim/models/iiwa7.urdf)");
  app.add_option("--tolerance-deg", options.tolerance_deg, "Arrival tolerance per joint [deg]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--startup-timeout-sec", options.startup_timeout_s, "Wait for the first ROBOT_STATE [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--reply-timeout-sec", options.reply_timeout_s,
                 "Wait for PLAN_CHECK_REPLY / REGISTRATION / MISALIGNMENT [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--move-timeout-sec", options.move_timeout_s,
                 "Wait for the arm to reach a configuration [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--trial-timeout-sec", options.trial_timeout_s, "Wait for the user's ALIGNMENT_TRIAL [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--robot-state-channel", options.robot_state_channel)->capture_default_str();
  app.add_option("--iiwa-command-channel", options.iiwa_command_channel)->capture_default_str();
  app.add_option("--plan-check-request-channel", options.plan_check_request_channel)->capture_default_str();
  app.add_option("--plan-check-reply-channel", options.plan_check_reply_channel)->capture_default_str();
  app.add_option("--session-control-channel", options.session_control_channel)->capture_default_str();
  app.add_option("--trial-channel", options.trial_channel)->capture_default_str();
  app.add_option("--registration-channel", options.registration_channel)->capture_default_str();
  app.add_option("--misalignment-request-channel", options.misalignment_request_channel)
      ->capture_default_str();
  app.add_option("--misalignment-channel", options.misalignment_channel)->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  orbed::ApplyCommonFlags(common);
  if (const char* env_run_id = std::getenv("ORBED_RUN_ID"); options.run_id.empty() && env_run_id != nullptr) {
    options.run_id = env_run_id;
  }
  try {
    if (scenario_path.empty()) {
      scenario_path = orbed::scenario::ScenarioSourcePath(orbed::viraal::kDefaultScenarioRelativePath);
    }
    options.config = orbed::viraal::LoadScenarioFile(scenario_path);
    orbed::viraal::ApplyOverrides(&options.config, trials, modes, q_deg);
    options.out = &std::cout;
    orbed::scenario::ViraalScenario scenario(common, options);
    return scenario.Run();
  } catch (const std::exception& e) {
    std::cerr << "orbed-scenario: " << e.what() << "\n";
    return 1;
  }
}
