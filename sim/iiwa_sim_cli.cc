#include "sim/iiwa_sim_cli.h"

#include <exception>

#include <CLI/CLI.hpp>

#include "runtime/flags.h"
#include "sim/iiwa_sim.h"

namespace orbed::sim {

int RunIiwaSim(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-iiwa-sim: simulated iiwa 7 arm (URDF + Bullet collision world) executing\n"
      "IIWA_COMMAND like a hand-guided arm; publishes IIWA_STATUS, ROBOT_STATE and\n"
      "COLLISION_STATUS every tick and answers PLAN_CHECK_REQUEST."};
  CommonFlags common("orbed-iiwa-sim");
  AddCommonFlags(&app, &common);
  IiwaSimOptions options;
  app.add_option("--urdf", options.urdf_path,
                 "Robot URDF (default: sim/models/iiwa7.urdf under $ORBED_SOURCE_DIR, else under the "
                 "source tree it was built from)");
  app.add_option("--scene", options.scene_path,
                 "Scene YAML (default: sim/models/scenes/trocar_or.yaml, found like --urdf)");
  app.add_option("--period-s", options.period_s, "Tick and status period [s] (0.005 = 200 Hz)")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--realtime-rate", options.realtime_rate,
                 "Sim seconds per wall second (1-100; for studies without a person in the loop; in "
                 "--lockstep the fastest)")
      ->capture_default_str();
  app.add_option("--steps-per-tick", options.steps_per_tick,
                 "Steps of --period-s per tick, which publishes once (1-1000; 0 = the realtime rate)")
      ->capture_default_str();
  app.add_flag("--lockstep", options.lockstep,
               "Before each step, wait until every process that follows the clock (--sim-time) has "
               "answered on SIM_CLOCK_ACK and nothing is in flight: runs do not depend on the machine's "
               "speed or the rate");
  app.add_option("--lockstep-timeout-s", options.lockstep_timeout_s,
                 "Wall seconds a lockstep round waits for a follower before going on without it")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option(
      "--arm", options.arm,
      "Be the arm NAME of the scene's `arms:` list (several arms): its base, its channels with the "
      "suffix _NAME (IIWA_STATUS_A1, ...), the other arms as obstacles from their ROBOT_STATE_<NAME> "
      "(default: the single arm, plain channel names)");
  app.add_option("--hold-for", options.hold_for,
                 "Hold the sim clock (publish only SIM_CLOCK, do not step) until PROCESS_STATUS shows the "
                 "process of this name running, so that a launch's followers of the clock start together "
                 "(empty: run from the start)");
  AddNumberListOption(&app, "--initial-q-deg", &options.initial_q_deg, 0,
                      "Initial joint angles q1,...,q7 [deg] (default: all 0)");
  app.add_option("--state-file", options.state_file,
                 "Keep the arm's measured configuration in this file and start from it when it exists "
                 "(crash recovery)");
  app.add_option("--state-save-period-s", options.state_save_period_s,
                 "Longest time between two saves of the state file while the arm moves [s]")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--stale-command-s", options.stale_command_s,
                 "Reject IIWA_COMMAND whose utime is further than this from the wall clock [s]; 0 = off")
      ->check(orbed::NonNegativeNumber())
      ->capture_default_str();
  app.add_option("--stop-margin-m", options.stop_margin_m, "Stop this far before contact [m]")
      ->check(orbed::NonNegativeNumber())
      ->capture_default_str();
  app.add_option("--report-distance-m", options.report_distance_m,
                 "COLLISION_STATUS lists pairs closer than this [m]")
      ->check(orbed::NonNegativeNumber())
      ->capture_default_str();
  app.add_option("--robot-name", options.robot_name, "robot_name on ROBOT_STATE")->capture_default_str();
  app.add_option("--iiwa-status-channel", options.iiwa_status_channel)->capture_default_str();
  app.add_option("--iiwa-command-channel", options.iiwa_command_channel)->capture_default_str();
  app.add_option("--robot-state-channel", options.robot_state_channel)->capture_default_str();
  app.add_option("--collision-status-channel", options.collision_status_channel)->capture_default_str();
  app.add_option("--plan-check-request-channel", options.plan_check_request_channel)->capture_default_str();
  app.add_option("--plan-check-reply-channel", options.plan_check_reply_channel)->capture_default_str();
  app.add_option("--sim-clock-channel", options.sim_clock_channel,
                 "Where each tick's stamp goes for the processes that follow the sim clock (--sim-time); "
                 "\"\" = nowhere")
      ->capture_default_str();
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  try {
    IiwaSim sim(common, options);
    return sim.Run();
  } catch (const std::exception& e) {
    err << "orbed-iiwa-sim: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::sim
