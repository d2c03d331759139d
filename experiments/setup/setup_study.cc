#include "experiments/setup/setup_study.h"

#include <cmath>
#include <deque>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>
#include <variant>

#include <orbed/alignment_trial_t.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/landmark_request_t.hpp>
#include <orbed/landmark_t.hpp>
#include <orbed/misalignment_request_t.hpp>
#include <orbed/misalignment_t.hpp>
#include <orbed/plan_check_reply_t.hpp>
#include <orbed/plan_check_request_t.hpp>
#include <orbed/session_control_t.hpp>

#include "base/hash.h"
#include "base/random.h"
#include "base/source_paths.h"
#include "experiments/setup/design.h"
#include "experiments/viraal/registration_service.h"
#include "hmd_emulator/hmd.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/assistant/assistant_machine.h"
#include "procs/fixed_display/fixed_display.h"
#include "procs/guidance/guidance.h"
#include "sim/arm_sim.h"
#include "sim/iiwa_status_check.h"
#include "sim/scene.h"

namespace orbed::setup {
namespace {

// The launch's numbers (scripts/launch/setup.yaml, base.yaml, what `scripts/orbed study` sets).
constexpr int kStepsPerTick = 10;                // steps_per_tick
constexpr int kRealtimeRate = 100;               // sim_rate: the pace only, no number depends on it
constexpr double kJointLimitSlackRad = 0.01;     // as orbed-assistant, orbed-hmd and orbed-guidance
constexpr double kSetupTickS = 0.01;             // orbed-setup's timer
constexpr double kAssistantStepS = 0.02;         // orbed-assistant's step_period_s
constexpr double kGuidanceRateHz = 30.0;         // orbed-guidance's rate_hz
constexpr double kGuidanceStaleS = 0.5;          // orbed-guidance's stale_after_s
constexpr double kFixedViewRateHz = 5.0;         // orbed-fixed-display's rate_hz
constexpr double kFixedViewStaleS = 1.0;         // orbed-fixed-display's stale_after_s
constexpr double kRegistrationStatePeriodS = 1;  // orbed-registration --state-period-s 1
constexpr double kPoseHz = 60.0;                 // orbed-hmd's pose_hz

// FIXED_VIEW as the assistant reads it: the monitor camera's position.
struct FixedView {
  Eigen::Vector3d p_WD;
};
struct HeadPose {
  bool truth{false};
  orbed::hmd_pose_t msg;
};
using Message =
    std::variant<orbed::iiwa_status_t, orbed::robot_state_t, orbed::collision_status_t, orbed::iiwa_command_t,
                 orbed::plan_check_request_t, orbed::plan_check_reply_t, orbed::session_control_t,
                 orbed::alignment_trial_t, orbed::registration_t, orbed::landmark_request_t,
                 orbed::landmark_t, orbed::misalignment_request_t, orbed::misalignment_t, HeadPose,
                 orbed::guidance_t, orbed::setup_task_t, orbed::setup_result_t, FixedView>;

// A timer on the sim clock as runtime/process.h runs it: deadlines k·period since the first
// SIM_CLOCK (every process is constructed before it), each run with the clock at its deadline.
struct SimTimer {
  int64_t period_ns{0};
  int64_t next_ns{0};
  explicit SimTimer(double period_s) : period_ns(std::llround(period_s * 1e9)), next_ns(period_ns) {}
};

std::string Shipped(const std::string& path, const char* relative) {
  return path.empty() ? SourceTreePath(relative) : path;
}

// What the user's launch gives its processes: the scene (the launch's `scene` argument: the sim,
// the headset, the monitor) and orbed-setup's options, as `scripts/orbed study` and RunSetup
// (procs/setup/setup_process.cc) make them.
struct Launch {
  std::string scene_path;
  SetupOptions setup;
};

Launch LaunchOf(const SetupUserOptions& o, const sim::RobotModel& model) {
  Launch launch;
  SetupOptions& s = launch.setup;
  s.user = o.user;
  s.run_id = o.run_id;
  s.modes = o.modes.empty() ? ModeOrderForSeed(o.user_seed) : o.modes;
  s.start_deg = o.start_deg;
  s.perfect_registration = o.perfect_registration;
  if (o.use_plan) {
    launch.scene_path = Shipped(o.scene_path, sim::kDefaultSceneRelativePath);
    s.targets_deg = PlanTargetsDeg(Shipped(o.plan_path, "experiments/setup/targets.json"), o.targets, model);
  } else {
    // `scripts/orbed study` gives the launch the drawn patient's scene (orbed-design draw), and
    // orbed-setup draws again with the patient fixed by that scene: the same pairs.
    const UserDesign design = UserDesignFor(Shipped(o.design_path, kDefaultDesignRelativePath), o.scene_path,
                                            o.user_seed, o.targets);
    launch.scene_path = o.scene_path.empty() ? SourceTreePath(design.scene) : o.scene_path;
    for (const DesignPair& p : design.pairs) {
      s.targets_deg.push_back(p.target_deg);
      s.starts_deg.push_back(p.start_deg);
      s.start_ids.push_back(p.start_id);
      s.target_ids.push_back(p.target_id);
    }
    s.retract = true;
    s.retract_scene_path = launch.scene_path;
  }
  s.alignment = viraal::LoadScenarioFile(Shipped(o.scenario_path, viraal::kDefaultScenarioRelativePath));
  s.alignment.trials = o.trials;
  s.request_deadline_s = 60.0;  // the launch file's --request-deadline-s
  return launch;
}

// One user's launch: the cores of its processes and the messages between them.
class UserBus {
 public:
  explicit UserBus(const SetupUserOptions& o)
      : options_(o),
        model_(sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath))),
        launch_(LaunchOf(o, model_)),
        sim_(SimOptions(launch_.scene_path)),
        headset_(HeadsetOptions(o, launch_.scene_path), o.hmd_process_seed, 0.0),
        service_({}, [](const std::string&, const std::string&) {}),
        machine_(model_, AssistantConfigOf(o), assistant::MachineOptions{}),
        conductor_(launch_.setup, model_),
        pose_timer_(1.0 / kPoseHz),
        registration_timer_(kRegistrationStatePeriodS),
        guidance_timer_(1.0 / kGuidanceRateHz),
        fixed_timer_(1.0 / kFixedViewRateHz),
        assistant_timer_(kAssistantStepS),
        setup_timer_(kSetupTickS) {
    // orbed-fixed-display's home view: the configured camera about the scene's base.
    const sim::Scene scene = sim::LoadSceneFile(launch_.scene_path);
    fixed_home_ = fixed_display::OrbitView::Through(fixed_display::kDefaultCamera_m,
                                                    fixed_display::OrbitCentre(scene.X_WR));
  }

  SetupRun Run() {
    sim_.Start(options_.start_utime, 0);
    const int64_t tick_us = sim_.tick_us();
    const int64_t max_ticks = static_cast<int64_t>(options_.max_sim_s * 1e6 / static_cast<double>(tick_us));
    for (int64_t k = 1; !conductor_.done(); ++k) {
      if (k > max_ticks) {
        Apply(conductor_.Abort(
            "in-process run: no end within " + std::to_string(options_.max_sim_s) + " s of sim time",
            HandlerTime()));
        break;
      }
      const sim::ArmSim::TickResult tick = sim_.Tick(k * sim_.tick_wall_ns());
      now_ns_ = k * tick_us * 1000;
      now_utime_ = sim_.NowUtime();
      // Round 1: the followers' timers that came due, on the previous tick's state.
      RunTimers();
      // The tick's state, then every message to the end (the later rounds).
      Send(sim_.IiwaStatus(now_utime_));
      Send(sim_.RobotState(now_utime_));
      Send(sim_.CollisionStatus(now_utime_, tick.closest));
      Deliver();
    }
    return conductor_.run();
  }

 private:
  static sim::IiwaSimOptions SimOptions(const std::string& scene_path) {
    sim::IiwaSimOptions o;
    o.urdf_path = SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath);
    o.scene_path = scene_path;
    o.realtime_rate = kRealtimeRate;
    o.steps_per_tick = kStepsPerTick;
    o.lockstep = true;
    return o;
  }
  static hmd::HmdOptions HeadsetOptions(const SetupUserOptions& o, const std::string& scene_path) {
    hmd::HmdOptions h;
    h.user_seed = o.user_seed;
    h.scene_path = scene_path;
    h.config_paths = o.headset_config_paths;
    h.threaded = false;
    return hmd::ResolveHmdOptions(h);
  }
  static assistant::AssistantConfig AssistantConfigOf(const SetupUserOptions& o) {
    assistant::AssistantConfig c = assistant::LoadAssistantConfig(
        Shipped(o.assistant_config_path, assistant::kDefaultConfigRelativePath));
    c.seed = o.user_seed;
    return c;
  }
  // The clock inside a timer (its deadline) and in a handler (the latest SIM_CLOCK).
  ConductorTime TimerTime(int64_t deadline_ns) const {
    return {1e-9 * static_cast<double>(deadline_ns), UtimeAt(deadline_ns)};
  }
  ConductorTime HandlerTime() const { return {1e-9 * static_cast<double>(now_ns_), now_utime_}; }
  int64_t UtimeAt(int64_t elapsed_ns) const {
    return now_utime_ - std::llround(static_cast<double>(now_ns_ - elapsed_ns) * 1e-3);
  }
  hmd::HeadsetClock HeadsetTime(const ConductorTime& t) const { return {t.t_s, t.utime, t.t_s, t.utime}; }

  void Send(Message m) { queue_.push_back(std::move(m)); }

  // Each process's due timers in the order of their deadlines (here one or two per process).
  void RunTimers() {
    for (; pose_timer_.next_ns <= now_ns_; pose_timer_.next_ns += pose_timer_.period_ns) {
      const hmd::Headset::PoseStep step = headset_.StepPose(HeadsetTime(TimerTime(pose_timer_.next_ns)));
      Send(HeadPose{false, step.poses.estimate});
      Send(HeadPose{true, step.poses.truth});
      Act(step.actions);
    }
    for (; registration_timer_.next_ns <= now_ns_;
         registration_timer_.next_ns += registration_timer_.period_ns) {
      if (auto state = service_.PeriodicState()) Send(*state);
    }
    for (; guidance_timer_.next_ns <= now_ns_; guidance_timer_.next_ns += guidance_timer_.period_ns) {
      const int64_t utime = UtimeAt(guidance_timer_.next_ns);
      if (guidance_ && have_q_ && utime - q_received_utime_ <= static_cast<int64_t>(kGuidanceStaleS * 1e6))
        Send(guidance_->Compute(q_rad_, utime));
    }
    for (; fixed_timer_.next_ns <= now_ns_; fixed_timer_.next_ns += fixed_timer_.period_ns) {
      const int64_t utime = UtimeAt(fixed_timer_.next_ns);
      const bool fresh = fixed_guidance_utime_ > 0 &&
                         utime - fixed_guidance_utime_ <= static_cast<int64_t>(kFixedViewStaleS * 1e6);
      if (fixed_X_WR_ && fresh && fixed_mode_ == orbed::guidance_t::MODE_FIXED_DISPLAY)
        Send(FixedView{fixed_home_.X_WD(fixed_display::OrbitCentre(*fixed_X_WR_)).translation()});
    }
    for (; assistant_timer_.next_ns <= now_ns_; assistant_timer_.next_ns += assistant_timer_.period_ns) {
      const ConductorTime t = TimerTime(assistant_timer_.next_ns);
      const assistant::StepOutput out = machine_.Step(t.t_s, t.utime);
      if (out.command) Send(*out.command);
      if (!out.failure.empty()) {
        Apply(conductor_.Abort("orbed-assistant failed: " + out.failure, HandlerTime()));
        return;
      }
      if (out.task_reply) Send(*out.task_reply);
    }
    for (; setup_timer_.next_ns <= now_ns_; setup_timer_.next_ns += setup_timer_.period_ns) {
      const ConductorTime t = TimerTime(setup_timer_.next_ns);
      if (!setup_started_) {
        // orbed-setup starts with its first input after the first SIM_CLOCK: this timer.
        setup_started_ = true;
        Apply(conductor_.Start(t));
      }
      Apply(conductor_.Tick(t));
    }
  }

  void Act(const hmd::HeadsetActions& a) {
    if (a.start) Send(*a.start);
    if (a.trial) Send(*a.trial);
    if (a.command) Send(*a.command);
    if (a.task) Send(*a.task);
  }

  void Apply(const SetupConductor::Actions& actions) {
    for (const scenario::ConductorAction& action : actions.viraal) {
      if (const auto* p = std::get_if<scenario::Publication>(&action))
        std::visit([this](const auto& msg) { Send(msg); }, p->message);
    }
    for (const SetupPublication& p : actions.publish)
      std::visit([this](const auto& msg) { Send(msg); }, p.message);
  }

  void Deliver() {
    while (!queue_.empty()) {
      Message m = std::move(queue_.front());
      queue_.pop_front();
      std::visit([this](const auto& msg) { Handle(msg); }, m);
      if (conductor_.done()) {
        queue_.clear();
        return;
      }
    }
  }

  // Every subscriber of each message, as the processes' shells hand it to their cores.
  void Handle(const orbed::iiwa_status_t& msg) {
    Eigen::VectorXd q;
    if (!sim::CheckIiwaStatus(msg, model_, kJointLimitSlackRad, &q).rejection_class.empty())
      throw std::runtime_error("in-process run: IIWA_STATUS refused");
    headset_.OnJoints(q);
    machine_.OnJoints(q);
    q_rad_ = q;  // orbed-guidance
    have_q_ = true;
    q_received_utime_ = now_utime_;
  }
  void Handle(const orbed::robot_state_t& msg) {
    const Eigen::Isometry3d X_WR = FromPose(msg.X_WR);
    headset_.OnRobotBase(X_WR);
    machine_.OnRobotState(X_WR, msg.motion_state);
    fixed_X_WR_ = X_WR;
    Apply(conductor_.OnRobotState(msg, HandlerTime()));
  }
  void Handle(const orbed::collision_status_t& msg) {
    Apply(conductor_.OnCollisionStatus(msg, HandlerTime()));
  }
  void Handle(const orbed::iiwa_command_t& msg) { sim_.AcceptCommand(msg, now_utime_); }
  void Handle(const orbed::plan_check_request_t& msg) {
    std::optional<Refusal> refusal;
    orbed::plan_check_reply_t reply = sim_.PlanCheckReply(msg, now_utime_, &refusal);
    reply.utime = now_utime_;
    Send(reply);
  }
  void Handle(const orbed::plan_check_reply_t& msg) {
    Apply(conductor_.OnPlanCheckReply(msg, HandlerTime()));
  }
  void Handle(const orbed::session_control_t& msg) {
    Act(headset_.OnSessionControl(msg, HeadsetTime(HandlerTime())));
    if (headset_.trial_ready()) Act(headset_.PublishReadyTrial(now_utime_));
    if (auto state = service_.HandleSessionControl(msg)) Send(*state);
  }
  void Handle(const orbed::alignment_trial_t& msg) {
    if (headset_.WantsTrial(msg)) Act(headset_.OnTrial(msg));
    if (auto state = service_.HandleTrial(msg)) Send(*state);
    Apply(conductor_.OnTrial(msg, HandlerTime()));
  }
  void Handle(const orbed::registration_t& msg) {
    if (headset_.WantsRegistration(msg)) headset_.OnRegistration(FromPose(msg.X_WV_mean));
    if (msg.valid) {
      Eigen::Isometry3d X_WV = FromPose(msg.X_WV_mean);
      if (options_.injection.active()) {
        const auto [d_W, a_W] = InjectionFor(options_.injection, options_.user_seed, msg.session_id);
        X_WV =
            InjectRegistrationError(X_WV, options_.injection.offset_m, options_.injection.tilt_rad, d_W, a_W);
      }
      machine_.OnRegistration(X_WV);
    }
    Apply(conductor_.OnRegistration(msg, HandlerTime()));
  }
  void Handle(const orbed::landmark_request_t& msg) { Send(service_.HandleLandmarkRequest(msg)); }
  void Handle(const orbed::landmark_t& msg) { Apply(conductor_.OnLandmark(msg, HandlerTime())); }
  void Handle(const orbed::misalignment_request_t& msg) { Send(service_.HandleMisalignmentRequest(msg)); }
  void Handle(const orbed::misalignment_t& msg) { Apply(conductor_.OnMisalignment(msg, HandlerTime())); }
  void Handle(const HeadPose& pose) {
    machine_.OnHeadPose(pose.truth, pose.msg.seq, FromPose(pose.msg.X_WH));
  }
  void Handle(const orbed::guidance_t& msg) {
    machine_.OnGuidance(msg);
    headset_.OnGuidance(msg, HandlerTime().t_s);
    fixed_mode_ = msg.mode;  // orbed-fixed-display
    fixed_guidance_utime_ = now_utime_;
  }
  void Handle(const orbed::setup_task_t& msg) {
    const assistant::TaskAnswer answer = machine_.OnSetupTask(msg);
    if (answer.reply) Send(*answer.reply);
    // orbed-guidance: a new task's target.
    if (msg.request_id != 0 && msg.request_id == guidance_request_id_) return;
    guidance::GuidanceTarget target;
    target.mode = msg.mode;
    target.q_target_rad = Eigen::Map<const Eigen::VectorXd>(msg.target_position.data(), msg.num_joints);
    guidance_.emplace(model_, target);
    guidance_request_id_ = msg.request_id;
  }
  void Handle(const orbed::setup_result_t& msg) { Apply(conductor_.OnSetupResult(msg, HandlerTime())); }
  void Handle(const FixedView& view) { machine_.OnMonitorCamera(view.p_WD, HandlerTime().t_s); }

  SetupUserOptions options_;
  sim::RobotModel model_;
  Launch launch_;
  sim::ArmSim sim_;
  hmd::Headset headset_;
  registration::RegistrationService service_;
  assistant::AssistantMachine machine_;
  SetupConductor conductor_;
  // orbed-guidance's state.
  std::optional<guidance::GuidanceCore> guidance_;
  int64_t guidance_request_id_{0};
  Eigen::VectorXd q_rad_;
  bool have_q_{false};
  int64_t q_received_utime_{0};
  // orbed-fixed-display's state.
  fixed_display::OrbitView fixed_home_;
  std::optional<Eigen::Isometry3d> fixed_X_WR_;
  int8_t fixed_mode_{-1};
  int64_t fixed_guidance_utime_{0};
  bool setup_started_{false};
  SimTimer pose_timer_, registration_timer_, guidance_timer_, fixed_timer_, assistant_timer_, setup_timer_;
  int64_t now_ns_{0};
  int64_t now_utime_{0};
  std::deque<Message> queue_;
};

}  // namespace

Eigen::Isometry3d InjectRegistrationError(const Eigen::Isometry3d& X_WV, double offset_m, double tilt_rad,
                                          const Eigen::Vector3d& direction_W, const Eigen::Vector3d& axis_W) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::AngleAxisd(tilt_rad, axis_W.normalized()).toRotationMatrix() * X_WV.linear();
  out.translation() = X_WV.translation() + offset_m * direction_W.normalized();
  return out;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> InjectionFor(const RegistrationInjection& injection,
                                                         uint64_t user_seed, const std::string& task_id) {
  if (!injection.random_direction)
    return {injection.direction_W.normalized(), injection.tilt_axis_W.normalized()};
  Random rng(SplitMix64(user_seed ^ Fnv1a64(task_id)));
  // Uniform on the sphere: z uniform in [-1, 1], azimuth uniform (Archimedes).
  const double z = rng.Uniform(-1.0, 1.0);
  const double phi = rng.Uniform(0.0, 2 * M_PI);
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  const double psi = rng.Uniform(0.0, 2 * M_PI);
  return {Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z),
          Eigen::Vector3d(std::cos(psi), std::sin(psi), 0)};
}

SetupRun RunSetupUser(const SetupUserOptions& options) {
  UserBus bus(options);
  return bus.Run();
}

}  // namespace orbed::setup
