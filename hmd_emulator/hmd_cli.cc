#include "hmd_emulator/hmd_cli.h"

#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "hmd_emulator/hmd_config.h"
#include "hmd_emulator/hmd_process.h"

namespace orbed::hmd {

int RunHmd(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-hmd: the emulated headset (SLAM pose stream, camera, gaze, reflective-AR displays,\n"
      "AR view) and its wearer, who performs a ViRAAl alignment trial on each SESSION_CONTROL\n"
      "REQUEST_TRIAL; --interactive puts a person in its place (OpenCV window)."};
  orbed::CommonFlags common("orbed-hmd");
  orbed::AddCommonFlags(&app, &common);
  orbed::AddSimTimeFlag(&app, &common);
  HmdOptions o;
  app.add_option("--urdf", o.urdf_path,
                 "Robot URDF (default: sim/models/iiwa7.urdf under $ORBED_SOURCE_DIR, else the source tree)");
  app.add_option("--scene", o.scene_path,
                 "Scene YAML (default: sim/models/scenes/trocar_or.yaml, found like --urdf)");
  app.add_option(
      "--config", o.config_paths,
      "YAML file(s) with slam:, user:, head_trajectory: and/or hmd: mappings, applied in order after "
      "the shipped hmd_emulator/config/{slam,user,viraal_walk,hmd}.yaml (repeatable)");
  app.add_option_function<std::uint64_t>(
      "--user-seed", [&o](const std::uint64_t& seed) { o.user_seed = seed; },
      "The emulated person (overrides user.seed): a different seed is a different person");
  app.add_option("--camera-hz", o.camera_hz,
                 "HMD_CAMERA rate [Hz], (0, 1000]; faster than the renderer keeps up with, a request that "
                 "finds the previous one still waiting replaces it, counted as the drop HMD_CAMERA/busy")
      ->capture_default_str();
  app.add_option("--pose-hz", o.pose_hz, "HMD_POSE / HMD_POSE_TRUTH rate [Hz], (0, 1000]")
      ->capture_default_str();
  app.add_option("--jpeg-quality", o.jpeg_quality, "JPEG quality of every image, 1..100")
      ->capture_default_str();
  app.add_option("--displays", o.displays,
                 "Reflective displays published live (placed by hmd.displays in the config)")
      ->capture_default_str();
  app.add_flag("--interactive", o.interactive,
               "A person aligns instead of the emulated user: a window with the AR view and a reflective "
               "display; keys nudge the virtual robot, Enter submits, h shows the keys");
  app.add_option("--screenshot", o.screenshot_path,
                 "With --interactive: write the window's image here at exit (PNG)");
  app.add_option("--scripted-keys", o.scripted_keys,
                 "With --interactive: keys typed one per refresh before real ones (\\n = Enter, \\e = Esc)");
  app.add_option("--state-file", o.state_file,
                 "Keep the session and its last trial in this file and continue from it when it exists "
                 "(crash recovery)");
  AddInstanceFlag(
      &app, "--headset", &o.headset,
      "One of several headsets: its own and its session's channels get the suffix _NAME "
      "(HMD_POSE_H1, HMD_CAMERA_H1, SESSION_CONTROL_H1, REGISTRATION_H1, ...; default: plain names)");
  AddInstanceFlag(&app, "--arm", &o.arm,
                  "Look at the arm NAME of the scene's `arms:` list: walk around its base and read its "
                  "channels (IIWA_STATUS_A1, ROBOT_STATE_A1, GUIDANCE_A1, ...; default: the single arm)");
  AddInstanceFlag(
      &app, "--collaborator", &o.collaborator,
      "Another headset (its --headset NAME) as this one's first reflective display: what its camera "
      "sees (it stands where its HMD_POSE_TRUTH_<NAME> says), the hologram drawn through a shared "
      "anchor (error: hmd.collaborator in --config); the emulated trials align with it");
  app.add_option("--iiwa-status-channel", o.iiwa_status_channel)->capture_default_str();
  app.add_option("--robot-state-channel", o.robot_state_channel)->capture_default_str();
  app.add_option("--iiwa-command-channel", o.iiwa_command_channel,
                 "Interactive: where keys , and . turn the arm")
      ->capture_default_str();
  app.add_option("--setup-task-channel", o.setup_task_channel,
                 "Interactive: where t, Enter sends the planned target")
      ->capture_default_str();
  app.add_option("--session-control-channel", o.session_control_channel)->capture_default_str();
  app.add_option("--registration-channel", o.registration_channel)->capture_default_str();
  app.add_option("--guidance-channel", o.guidance_channel)->capture_default_str();
  app.add_option("--hmd-pose-channel", o.hmd_pose_channel)->capture_default_str();
  app.add_option("--hmd-pose-truth-channel", o.hmd_pose_truth_channel)->capture_default_str();
  app.add_option("--camera-channel", o.camera_channel)->capture_default_str();
  app.add_option("--gaze-channel", o.gaze_channel)->capture_default_str();
  app.add_option("--reflective-channel", o.reflective_channel)->capture_default_str();
  app.add_option("--ar-view-channel", o.ar_view_channel)->capture_default_str();
  app.add_option("--trial-channel", o.trial_channel)->capture_default_str();
  app.add_option("--holograms-channel", o.holograms_channel,
                 "The holograms an hl2ss client placed (orbed-hl2ss), drawn in AR_VIEW and the displays")
      ->capture_default_str();
  bool check_config = false;
  app.add_flag("--check-config", check_config,
               "Read the shipped configuration and every --config over it as a run would, say whether "
               "it is valid (exit code 0, else 2), and exit");
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  if (check_config) {
    try {
      std::vector<std::string> paths;
      for (const auto& rel : DefaultHmdConfigRelativePaths()) paths.push_back(HmdSourcePath(rel));
      paths.insert(paths.end(), o.config_paths.begin(), o.config_paths.end());
      LoadHmdConfigs(paths);
      out << "orbed-hmd: the configuration is valid (" << paths.size() << " files)\n";
      return 0;
    } catch (const std::exception& e) {
      err << "orbed-hmd: " << e.what() << "\n";
      return 2;
    }
  }
  try {
    HmdProcess hmd(common, o);
    return hmd.Run();
  } catch (const std::exception& e) {
    err << "orbed-hmd: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::hmd
