#include "experiments/viraal/viraal_study.h"

#include <memory>
#include <stdexcept>
#include <utility>

#include <orbed/session_control_t.hpp>

#include "base/source_paths.h"
#include "experiments/viraal/exchange.h"
#include "experiments/viraal/metrics.h"
#include "experiments/viraal/registration_service.h"
#include "hmd_emulator/headset_trial.h"
#include "hmd_emulator/hmd_config.h"
#include "hmd_emulator/user_model.h"
#include "lcmtypes/contract/conversions.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::study {
namespace {

// What orbed-registration would have refused ends the study: the live run would have failed too.
registration::RegistrationService MakeService() {
  return registration::RegistrationService({}, [](const std::string& key, const std::string& reason) {
    throw std::runtime_error("orbed-registration would refuse " + key + ": " + reason);
  });
}

orbed::session_control_t Control(int8_t command, const std::string& session_id, const viraal::ModeSpec& mode,
                                 int8_t method) {
  orbed::session_control_t msg{};
  msg.session_id = session_id;
  msg.command = command;
  msg.display_mode = mode.display_mode;
  msg.num_mirrors = mode.num_mirrors;
  msg.method = method;
  return msg;
}

const orbed::misalignment_t& Checked(const orbed::misalignment_t& reply) {
  if (!reply.valid)
    throw std::runtime_error("orbed-registration refused a misalignment request: " + reply.reason);
  return reply;
}

std::string UrdfPath(const StudyOptions& options) {
  return options.urdf_path.empty() ? SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath)
                                   : options.urdf_path;
}

std::string ScenePath(const StudyOptions& options) {
  return options.scene_path.empty() ? SourceTreePath(sim::kDefaultSceneRelativePath) : options.scene_path;
}

}  // namespace

viraal::RunResults RunViraalStudy(const StudyOptions& options) {
  const viraal::ScenarioConfig& scenario = options.scenario;
  const std::string urdf_path = UrdfPath(options);
  const std::string scene_path = ScenePath(options);

  // The conductor's model (landmarks and centroid) and the headset's (with the scene's tool).
  const sim::RobotModel conductor_model = sim::RobotModel::LoadFile(urdf_path);
  viraal::ValidateScenarioConfig(scenario, conductor_model.num_joints());
  const viraal::RobotPointSet points(conductor_model, scenario.landmarks);
  const sim::Scene scene = sim::LoadSceneFile(scene_path);
  const sim::RobotModel headset_model = sim::LoadRobotForScene(urdf_path, scene);
  std::vector<std::string> headset_paths;
  for (const auto& relative : hmd::DefaultHmdConfigRelativePaths())
    headset_paths.push_back(hmd::HmdSourcePath(relative));
  headset_paths.insert(headset_paths.end(), options.headset_config_paths.begin(),
                       options.headset_config_paths.end());
  hmd::HmdConfigSet headset = hmd::LoadHmdConfigs(headset_paths);
  if (options.user_seed) headset.user.seed = *options.user_seed;
  const Eigen::Isometry3d X_WV_start = hmd::EmulatedUser(headset.user).StartPose(scene.X_WR);
  const std::string user_id = "emulated-seed-" + std::to_string(headset.user.seed);

  // ROBOT_STATE's truth, as orbed-iiwa-sim publishes it.
  const orbed::pose_t X_WR = ToPose(scene.X_WR);
  for (size_t k = 0; k < scenario.configurations_deg.size(); ++k) {
    const std::string problem =
        conductor_model.ValidateJointVector(sim::DegToRad(ToVectorX(scenario.configurations_deg[k])));
    if (!problem.empty()) throw std::invalid_argument("configuration " + std::to_string(k) + ": " + problem);
  }

  viraal::RunResults results;
  results.run_id = options.run_id;
  results.seed = options.seed;
  results.landmarks = scenario.landmarks;
  results.configurations_deg = scenario.configurations_deg;
  results.X_WR = FromPose(X_WR);

  registration::RegistrationService service = MakeService();
  const int total = scenario.trials * static_cast<int>(scenario.modes.size());
  int done = 0;
  for (const viraal::ModeSpec& mode : scenario.modes) {
    viraal::SessionResult session;
    session.mode = mode.name;
    session.session_id = options.run_id + "-" + mode.name;
    session.display_mode = mode.display_mode;
    session.num_mirrors = mode.num_mirrors;
    if (mode.num_mirrors > 0) session.capture_waypoints = scenario.capture_waypoints;
    service.HandleSessionControl(
        Control(orbed::session_control_t::START, session.session_id, mode, scenario.method));

    std::vector<viraal::RobotPoints> session_points;
    hmd::SessionMapCache session_map;  // each trial one walk on from the last, as orbed-hmd does
    for (int i = 0; i < scenario.trials; ++i) {
      // The arm lands on the commanded configuration; the headset reads it from IIWA_STATUS.
      const std::vector<double>& q_deg = scenario.configurations_deg[i % scenario.configurations_deg.size()];
      const Eigen::VectorXd q_rad = sim::DegToRad(ToVectorX(q_deg));
      hmd::HeadsetTrialInputs inputs;
      hmd::SetRobotAt(headset_model, q_rad, &inputs);
      inputs.p_RL = hmd::AnnotationLandmarkPoints(headset_model, headset.hmd, q_rad);
      inputs.X_WR = FromPose(X_WR);
      inputs.X_WV_start = X_WV_start;
      inputs.process_seed = options.seed;
      inputs.session_id = session.session_id;
      inputs.trial_index = i;
      inputs.num_mirrors = mode.num_mirrors;
      if (mode.num_mirrors > 0) inputs.capture_waypoints = scenario.capture_waypoints;
      const hmd::TrialOutcome outcome = hmd::RunHeadsetTrial(headset, inputs, &session_map);

      // ALIGNMENT_TRIAL as orbed-hmd publishes it.
      orbed::alignment_trial_t trial{};
      trial.session_id = session.session_id;
      trial.trial_index = i;
      trial.display_mode = mode.display_mode;
      trial.num_mirrors = mode.num_mirrors;
      trial.num_joints = static_cast<int32_t>(q_rad.size());
      trial.joint_position = FromVectorX(q_rad);
      trial.X_WV = ToPose(outcome.alignment.X_WV);
      trial.duration_s = outcome.alignment.duration_s;
      trial.user_id = user_id;
      hmd::SetAnnotationFields(outcome.annotation, &trial);
      service.HandleTrial(trial);

      const viraal::RobotPoints trial_points = viraal::TrialPoints(points, trial);
      session_points.push_back(trial_points);
      viraal::AlignmentError error = viraal::TrialError(X_WR, trial, trial_points);
      // The annotation, triangulated by the server as orbed-scenario asks it over the bus.
      const auto checked = CheckAlignmentTrial(trial, conductor_model.num_joints());
      if (const auto* refusal = std::get_if<orbed::Refusal>(&checked)) {
        throw std::runtime_error("trial " + std::to_string(i) + " of '" + session.session_id +
                                 "': " + refusal->reason);
      }
      std::vector<orbed::landmark_t> landmarks;
      for (const orbed::landmark_request_t& request :
           viraal::LandmarkRequests(std::get<orbed::AlignmentTrial>(checked), 0, 0)) {
        landmarks.push_back(service.HandleLandmarkRequest(request));
      }
      if (!landmarks.empty()) error = viraal::WithAnnotation(error, landmarks);
      if (const auto eye = viraal::AlignmentViewpoint(std::get<orbed::AlignmentTrial>(checked)))
        error = viraal::WithViewer(error, *eye);
      const orbed::misalignment_t misalignment = Checked(
          service.HandleMisalignmentRequest(viraal::MisalignmentRequest(error, session.session_id, 0, i)));
      session.trials.push_back(viraal::TrialResultFrom(trial, X_WR, viraal::Measures(error, misalignment),
                                                       error.p_W_real_annotated, error.p_WE));
      if (options.progress) options.progress(++done, total);
    }

    const auto mean = service.HandleSessionControl(
        Control(orbed::session_control_t::COMPUTE, session.session_id, mode, scenario.method));
    if (!mean || !mean->valid) {
      throw std::runtime_error("session '" + session.session_id + "': orbed-registration has no valid mean");
    }
    const viraal::AlignmentError error = viraal::MeanError(
        X_WR, *mean, session_points, viraal::AnnotatedRealLandmarks(session), viraal::ViewerEyes(session));
    const orbed::misalignment_t misalignment = Checked(
        service.HandleMisalignmentRequest(viraal::MisalignmentRequest(error, session.session_id, 0, -1)));
    session.mean = viraal::MeanResultFrom(*mean, viraal::Measures(error, misalignment));
    service.HandleSessionControl(
        Control(orbed::session_control_t::STOP, session.session_id, mode, scenario.method));
    results.sessions.push_back(std::move(session));
  }
  results.ok = true;
  return results;
}

std::vector<GroupMean> GroupMeans(const viraal::SessionResult& session, int group_size,
                                  const std::vector<std::string>& landmarks, int8_t method,
                                  const std::string& urdf_path) {
  if (group_size < 1) throw std::invalid_argument("group size must be >= 1");
  const sim::RobotModel model = sim::RobotModel::LoadFile(
      urdf_path.empty() ? SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath) : urdf_path);
  const viraal::RobotPointSet points(model, landmarks);
  const viraal::ModeSpec mode{session.mode, static_cast<int8_t>(session.display_mode), session.num_mirrors};

  std::vector<GroupMean> out;
  const int groups = static_cast<int>(session.trials.size()) / group_size;
  for (int g = 0; g < groups; ++g) {
    registration::RegistrationService service = MakeService();
    const std::string id = session.session_id + "-group-" + std::to_string(g);
    service.HandleSessionControl(Control(orbed::session_control_t::START, id, mode, method));
    // The group as a session of its own: its trials, what the user annotated in them, their eyes.
    viraal::SessionResult group;
    std::vector<viraal::RobotPoints> group_points;
    for (int k = 0; k < group_size; ++k) {
      const viraal::TrialResult& result = session.trials[g * group_size + k];
      orbed::alignment_trial_t trial = viraal::TrialMessageFrom(result, session, 0);
      trial.session_id = id;
      trial.trial_index = k;
      service.HandleTrial(trial);
      group_points.push_back(viraal::TrialPoints(points, trial));
      group.trials.push_back(result);
    }
    const auto mean =
        service.HandleSessionControl(Control(orbed::session_control_t::COMPUTE, id, mode, method));
    if (!mean || !mean->valid) throw std::runtime_error("group '" + id + "': no valid mean");
    const orbed::pose_t X_WR = ToPose(group.trials.front().X_WR);
    const viraal::AlignmentError error = viraal::MeanError(
        X_WR, *mean, group_points, viraal::AnnotatedRealLandmarks(group), viraal::ViewerEyes(group));
    const orbed::misalignment_t misalignment =
        Checked(service.HandleMisalignmentRequest(viraal::MisalignmentRequest(error, id, 0, g)));
    out.push_back({g * group_size, group_size, viraal::Measures(error, misalignment)});
  }
  return out;
}

std::vector<GroupMean> GroupMeans(const StudyOptions& options, const viraal::SessionResult& session,
                                  int group_size) {
  return GroupMeans(session, group_size, options.scenario.landmarks, options.scenario.method,
                    UrdfPath(options));
}

}  // namespace orbed::study
