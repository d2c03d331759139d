#include "procs/registration_server/registration_server_cli.h"

#include <exception>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include "procs/registration_server/mean_command.h"
#include "procs/registration_server/registration_server_process.h"
#include "procs/registration_server/send_command.h"
#include "runtime/flags.h"

namespace orbed::registration {

int RunRegistration(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-registration: SE(3) averaging of alignment trials (paper eqs. 2-3), landmark\n"
      "triangulation and misalignment evaluation. Without a subcommand: the LCM server."};
  app.require_subcommand(0, 1);

  // Server flags.
  CommonFlags common("orbed-registration");
  AddCommonFlags(&app, &common);
  AddSimTimeFlag(&app, &common);
  RegistrationServerOptions server;
  std::vector<double> server_centroid_m;
  app.add_option("--state-period-s", server.state_period_s, "Period of the full-state REGISTRATION (0 = off)")
      ->check(orbed::NonNegativeNumber())
      ->capture_default_str();
  app.add_option("--journal", server.journal_path,
                 "Session journal: replayed at start, so a restarted server continues its session "
                 "(created if missing)");
  AddNumberListOption(&app, "--model-centroid-m", &server_centroid_m, 3,
                      "Average translations about this model centroid p_VC: x,y,z [m, in V]");
  app.add_option("--k-mad", server.service.outlier.k_mad, "Robust mode: reject beyond median + k*MAD")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--min-ray-angle-deg", server.service.triangulation.min_ray_angle_deg,
                 "Landmarks: rays closer than this to parallel are rejected")
      ->check(orbed::NumberIn(0.0, 89.0))
      ->capture_default_str();
  AddInstanceFlag(
      &app, "--headset", &server.headset,
      "The registration of headset NAME (one of several): every channel below gets the suffix _NAME "
      "(SESSION_CONTROL_H1, ALIGNMENT_TRIAL_H1, REGISTRATION_H1, ...)");
  app.add_option("--trial-channel", server.trial_channel)->capture_default_str();
  app.add_option("--registration-channel", server.registration_channel)->capture_default_str();
  app.add_option("--session-control-channel", server.session_control_channel)->capture_default_str();
  app.add_option("--landmark-request-channel", server.landmark_request_channel)->capture_default_str();
  app.add_option("--landmark-channel", server.landmark_channel)->capture_default_str();
  app.add_option("--misalignment-request-channel", server.misalignment_request_channel)
      ->capture_default_str();
  app.add_option("--misalignment-channel", server.misalignment_channel)->capture_default_str();

  // The offline command.
  MeanCommandOptions mean_options;
  std::vector<double> mean_centroid_m;
  CLI::App* mean =
      app.add_subcommand("mean", "Offline SE(3) mean of a trial file (qw,qx,qy,qz,tx,ty,tz per line)");
  mean->add_option("--input", mean_options.input_path,
                   "Trial file, one qw,qx,qy,qz,tx,ty,tz per line; '-' = stdin")
      ->required();
  mean->add_flag("--robust", mean_options.robust,
                 "Reject outlying trials (L1 median + k*MAD) before the Karcher mean");
  mean->add_flag("--json", mean_options.json, "Print one JSON object instead of a text report");
  AddNumberListOption(mean, "--model-centroid-m", &mean_centroid_m, 3,
                      "Average translations about this model centroid p_VC: x,y,z [m, in V]");

  // Feed a trial file to a running server.
  SendCommandOptions send_options;
  CLI::App* send = app.add_subcommand(
      "send", "Send a trial file to a running orbed-registration as one session and print its mean");
  send->add_option("--input", send_options.input_path,
                   "Trial file, one qw,qx,qy,qz,tx,ty,tz per line; '-' = stdin")
      ->required();
  send->add_option("--session-id", send_options.session_id, "Session id to use")->capture_default_str();
  send->add_flag("--robust", send_options.robust, "Ask for the robust mean");
  send->add_option("--timeout-s", send_options.timeout_s, "How long to wait for the answer")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();

  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;

  if (send->parsed()) {
    send_options.lcm_url = common.lcm_url;
    send_options.session_control_channel = server.session_control_channel;
    send_options.trial_channel = server.trial_channel;
    send_options.registration_channel = server.registration_channel;
    return RunSendCommand(send_options, out, err);
  }

  if (mean->parsed()) {
    if (mean_centroid_m.size() == 3) {
      mean_options.p_VC = Eigen::Vector3d(mean_centroid_m[0], mean_centroid_m[1], mean_centroid_m[2]);
    }
    return RunMeanCommand(mean_options, out, err);
  }

  if (server_centroid_m.size() == 3) {
    server.service.p_VC = Eigen::Vector3d(server_centroid_m[0], server_centroid_m[1], server_centroid_m[2]);
  }
  try {
    RegistrationServer process(common, server);
    return process.Run();
  } catch (const std::exception& e) {
    err << "orbed-registration: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::registration
