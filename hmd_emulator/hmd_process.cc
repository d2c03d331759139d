#include "hmd_emulator/hmd_process.h"

#include <chrono>
#include <cstdlib>
#include <stdexcept>

#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>

#include "base/format.h"
#include "base/log.h"
#include "lcmtypes/contract/alignment_trial.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/holograms.h"
#include "lcmtypes/contract/validation.h"
#include "sim/guidance_messages.h"
#include "sim/iiwa_status_check.h"

namespace orbed::hmd {
namespace {

constexpr char kWindowName[] = "orbed-hmd";
constexpr double kInteractiveHz = 30.0;
constexpr double kJointLimitSlackRad = 0.01;
using Job = ImagePipeline::Job;

double MonotonicSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

HmdProcess::HmdProcess(const orbed::CommonFlags& flags, const HmdOptions& options)
    : headset_(std::make_unique<Headset>(ResolveHmdOptions(options), flags.seed, MonotonicSeconds())) {
  ConnectToTheBus(flags);
  BuildImagePipeline();
  AddTimers();
  ORBED_LOG(kInfo) << headset_->Summary();
}

template <typename Message>
void HmdProcess::Listen(const std::string& channel,
                        void (HmdProcess::*handler)(const Message&, const std::string&)) {
  process_->Subscribe<Message>(channel, [this, handler](const Message& m, const std::string& ch, int64_t) {
    (this->*handler)(m, ch);
  });
}

// process_ (on the clock of the arm it looks at) and every subscription.
void HmdProcess::ConnectToTheBus(const orbed::CommonFlags& flags) {
  const HmdOptions& o = headset_->options();
  orbed::CommonFlags process_flags = flags;
  process_flags.sim_clock_arm = o.arm;  // --sim-time follows the clock of the arm it looks at
  process_ = std::make_unique<orbed::Process>(process_flags);
  Listen(o.iiwa_status_channel, &HmdProcess::OnIiwaStatus);
  Listen(o.robot_state_channel, &HmdProcess::OnRobotState);
  Listen(o.session_control_channel, &HmdProcess::OnSessionControl);
  Listen(o.registration_channel, &HmdProcess::OnRegistration);
  Listen(o.guidance_channel, &HmdProcess::OnGuidance);
  if (!o.collaborator.empty())
    Listen(channels::ForHeadset(channels::kHmdPoseTruth, o.collaborator), &HmdProcess::OnCollaboratorPose);
  Listen(o.trial_channel, &HmdProcess::OnTrial);
  Listen(o.holograms_channel, &HmdProcess::OnHolograms);
}

// pipeline_: the camera frame, reflective views and AR view, published through process_.
void HmdProcess::BuildImagePipeline() {
  const HmdOptions& o = headset_->options();
  ImagePipelineOutputs out;  // called on the worker thread when threaded
  orbed::Process* process = process_.get();
  // Not publications a lockstep round waits on: no process acts on them within a sim tick.
  const auto publish = [process](const std::string& ch) {
    return [process, ch](const auto& m) { process->PublishControl(ch, m); };
  };
  out.camera = publish(o.camera_channel);
  out.reflective = publish(o.reflective_channel);
  out.ar_view = publish(o.ar_view_channel);
  out.error = [process](const std::string& error, int64_t count) {
    // Shown as last_error on the heartbeat; an engine error must not take the process down.
    process->SetLastError(error);
    if (count <= 5) ORBED_LOG(kError) << error;
  };
  pipeline_ = std::make_unique<ImagePipeline>(headset_->robot_model(), headset_->stream().scene_objects(),
                                              headset_->PipelineOptions(), out);
}

// The pose and gaze timers on the process clock, the rendered streams' on the wall clock. Named by
// what they publish: a timer that falls behind counts its skipped deadlines as "timer/<channel>".
void HmdProcess::AddTimers() {
  const HmdOptions& o = headset_->options();
  const auto tick = [this](void (HmdProcess::*f)()) { return [this, f] { (this->*f)(); }; };
  process_->AddTimer(1.0 / o.pose_hz, tick(&HmdProcess::PublishPose), o.hmd_pose_channel);
  process_->AddTimer(1.0 / config().hmd.gaze_hz, tick(&HmdProcess::PublishGaze), o.gaze_channel);
  // The rendered streams keep wall rates also with --sim-time (see "Clocks" in hmd_process.h).
  process_->AddWallTimer(1.0 / o.camera_hz, tick(&HmdProcess::RequestCamera), o.camera_channel);
  if (o.displays > 0) {
    process_->AddWallTimer(1.0 / config().hmd.reflective_hz, tick(&HmdProcess::RequestReflective),
                           o.reflective_channel);
  }
  process_->AddWallTimer(1.0 / config().hmd.ar_view_hz, tick(&HmdProcess::RequestArView), o.ar_view_channel);
  if (o.interactive)
    process_->AddWallTimer(1.0 / kInteractiveHz, tick(&HmdProcess::InteractiveTick), "interactive");
}

HmdProcess::~HmdProcess() {
  pipeline_.reset();  // joins the worker before anything it uses goes
  if (window_open_) cv::destroyAllWindows();
}

void HmdProcess::Flush() { pipeline_->Flush(); }

HeadsetClock HmdProcess::Now() const {
  return HeadsetClock{process_->ClockSeconds(), process_->ClockUtime(), MonotonicSeconds(), NowMicros()};
}

void HmdProcess::Act(const HeadsetActions& actions, const std::string& channel) {
  const HmdOptions& o = headset_->options();
  if (actions.refusal) process_->Reject(channel + "/" + actions.refusal->key, actions.refusal->reason);
  if (actions.start) process_->Publish(o.session_control_channel, *actions.start);
  std::string error;
  if (actions.save && !o.state_file.empty() && !SaveSession(o.state_file, headset_->saved(), &error)) {
    process_->SetLastError(error);
    ORBED_LOG(kError) << error;
  }
  if (actions.trial) process_->Publish(o.trial_channel, *actions.trial);
  if (actions.command) process_->Publish(o.iiwa_command_channel, *actions.command);
  if (actions.task) process_->Publish(o.setup_task_channel, *actions.task);
  if (actions.recapture) pipeline_->RequestRecapture(*actions.recapture);
  if (actions.stop) process_->RequestStop();
}

void HmdProcess::PublishPose() {
  const Headset::PoseStep step = headset_->StepPose(Now());
  process_->Publish(options().hmd_pose_channel, step.poses.estimate);
  process_->Publish(options().hmd_pose_truth_channel, step.poses.truth);
  Act(step.actions);
}

void HmdProcess::PublishGaze() {
  if (const auto gaze = headset_->Gaze()) process_->Publish(options().gaze_channel, *gaze);
}

// A request that replaces one the renderer has not started is a frame never made: a drop
// "<channel>/busy" on the heartbeat.
void HmdProcess::Request(Job job, const std::string& channel) {
  if (pipeline_->Post(job, headset_->Inputs(process_->ClockSeconds())))
    process_->CountDrop(channel + "/busy");
}
void HmdProcess::RequestCamera() { Request(Job::kCamera, options().camera_channel); }
void HmdProcess::RequestReflective() { Request(Job::kReflective, options().reflective_channel); }
void HmdProcess::RequestArView() { Request(Job::kArView, options().ar_view_channel); }

void HmdProcess::OnSessionControl(const orbed::session_control_t& msg, const std::string& channel) {
  Act(headset_->OnSessionControl(msg, Now()), channel);
  // An emulated trial is stamped once done (on the wall clock it took time to run).
  if (headset_->trial_ready()) Act(headset_->PublishReadyTrial(process_->ClockUtime()));
}

void HmdProcess::OnIiwaStatus(const orbed::iiwa_status_t& msg, const std::string& channel) {
  Eigen::VectorXd q;
  const sim::IiwaStatusProblem problem =
      sim::CheckIiwaStatus(msg, headset_->robot_model(), kJointLimitSlackRad, &q);
  if (!problem.rejection_class.empty())
    return process_->Reject(channel + "/" + problem.rejection_class, problem.reason);
  headset_->OnJoints(q);
}

void HmdProcess::OnCollaboratorPose(const orbed::hmd_pose_t& msg, const std::string& channel) {
  const std::string error = CheckWorldPose(msg.X_WC, "X_WC");
  if (!error.empty()) return process_->Reject(channel + "/pose", error);
  headset_->OnCollaboratorCamera(FromPose(msg.X_WC), msg.utime);
}

void HmdProcess::OnRobotState(const orbed::robot_state_t& msg, const std::string& channel) {
  const std::string error = CheckPose(msg.X_WR, "X_WR");
  if (!error.empty()) return process_->Reject(channel + "/pose", error);
  headset_->OnRobotBase(FromPose(msg.X_WR));
}

void HmdProcess::OnGuidance(const orbed::guidance_t& msg, const std::string& channel) {
  const std::string problem = guidance::CheckGuidance(msg, headset_->robot_model(), kJointLimitSlackRad);
  if (!problem.empty()) return process_->Reject(channel + "/field", problem);
  headset_->OnGuidance(msg, process_->ClockSeconds());
}

void HmdProcess::OnHolograms(const orbed::hologram_scene_t& msg, const std::string& channel) {
  if (const auto refusal = CheckHologramScene(msg))
    return process_->Reject(channel + "/" + refusal->key, refusal->reason);
  headset_->OnHolograms(msg, process_->ClockSeconds());
}

void HmdProcess::OnRegistration(const orbed::registration_t& msg, const std::string& channel) {
  if (!headset_->WantsRegistration(msg)) return;
  const std::string error = CheckPose(msg.X_WV_mean, "X_WV_mean");
  if (!error.empty()) return process_->Reject(channel + "/pose", error);
  headset_->OnRegistration(FromPose(msg.X_WV_mean));
}

void HmdProcess::OnTrial(const orbed::alignment_trial_t& msg, const std::string& channel) {
  if (!headset_->WantsTrial(msg)) return;  // not ours
  const auto checked = CheckAlignmentTrial(msg, headset_->robot_model().num_joints());
  if (const auto* refusal = std::get_if<Refusal>(&checked))
    return process_->Reject(channel + "/" + refusal->key, refusal->reason);
  Act(headset_->OnTrial(msg));
}

void HmdProcess::HandleKey(int key) { Act(headset_->HandleKey(key, Now())); }

cv::Mat HmdProcess::CurrentWindowImage() {
  const cv::Mat reflective = pipeline_->LatestReflective(headset_->interactive().shown_display());
  return headset_->Window(pipeline_->LatestArView(), reflective, process_->ClockSeconds());
}

void HmdProcess::InteractiveTick() {
  pipeline_->Post(Job::kArView, headset_->Inputs(process_->ClockSeconds()), false);  // the window's
  const cv::Mat window = CurrentWindowImage();
  if (window_open_) cv::imshow(kWindowName, window);
  const int key = window_open_ ? cv::waitKey(1) : -1;
  const int scripted = headset_->interactive().NextScriptedKey();
  if (scripted >= 0) HandleKey(scripted);
  if (key >= 0) HandleKey(key);
}

int HmdProcess::Run() {
  const HmdOptions& o = headset_->options();
  if (o.interactive) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) {
      throw std::runtime_error(
          "--interactive needs an X display ($DISPLAY is not set); on a headless machine run "
          "it under `xvfb-run -a`");
    }
    try {
      cv::namedWindow(kWindowName, cv::WINDOW_AUTOSIZE);
    } catch (const cv::Exception& e) {
      throw std::runtime_error(std::string("--interactive: cannot open a window: ") + e.what());
    }
    window_open_ = true;
    headset_->interactive().RestartTimer(MonotonicSeconds());
    for (const auto& line : InteractiveHelpLines()) ORBED_LOG(kInfo) << "keys: " << line;
  }
  const int code = process_->Run();
  pipeline_->Flush();
  ORBED_LOG(kInfo) << "camera frames rendered " << pipeline_->rendered() << ", reused " << pipeline_->reused()
                   << ", requests skipped (worker busy) " << pipeline_->skipped();
  if (o.interactive && !o.screenshot_path.empty()) {
    const cv::Mat image = CurrentWindowImage();
    if (!cv::imwrite(o.screenshot_path, image)) {
      ORBED_LOG(kError) << "cannot write the screenshot " << o.screenshot_path;
      return 1;
    }
    ORBED_LOG(kInfo) << "screenshot " << o.screenshot_path << " (" << image.cols << "x" << image.rows << ")";
  }
  return code;
}

}  // namespace orbed::hmd
