#include "experiments/setup/setup_conductor.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <utility>

#include <orbed/guidance_t.hpp>

#include "base/format.h"
#include "base/json.h"
#include "base/json_fields.h"
#include "base/random.h"
#include "base/units.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/validation.h"
#include "sim/guidance_messages.h"

namespace orbed::setup {
namespace {

std::string ModeName(int8_t mode) { return guidance::GuidanceModeName(mode); }

bool Stopped(int8_t motion_state) {
  return motion_state == orbed::robot_state_t::MOTION_STOPPED_BEFORE_COLLISION ||
         motion_state == orbed::robot_state_t::MOTION_IN_COLLISION;
}

}  // namespace

Docking DockingError(const sim::RobotModel& model, const std::vector<double>& target_deg,
                     const std::vector<double>& reached_deg) {
  const size_t n = static_cast<size_t>(model.num_joints());
  if (target_deg.size() != n || reached_deg.size() != n)
    throw std::invalid_argument("DockingError: joint vectors must have " + std::to_string(n) + " values");
  Eigen::VectorXd q_target(n), q_reached(n);
  for (size_t i = 0; i < n; ++i) {
    q_target[i] = target_deg[i] * kDegToRad;
    q_reached[i] = reached_deg[i] * kDegToRad;
  }
  const Eigen::Isometry3d X_RT_target = model.CalcToolTipPose(q_target);
  const Eigen::Isometry3d X_RT_reached = model.CalcToolTipPose(q_reached);
  const Eigen::Vector3d z_target = X_RT_target.linear().col(2);
  const Eigen::Vector3d z_reached = X_RT_reached.linear().col(2);
  Docking d;
  d.tip_mm = (X_RT_reached.translation() - X_RT_target.translation()).norm() * 1e3;
  // atan2 of |a × b| and a · b: accurate at small and large angles alike.
  d.axis_deg = std::atan2(z_target.cross(z_reached).norm(), z_target.dot(z_reached)) * kRadToDeg;
  return d;
}

std::string SetupRunJson(const SetupRun& run, bool partial) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("user").String(run.user);
  json.Key("run_id").String(run.run_id);
  if (!run.provenance.empty()) json.Key("provenance").String(run.provenance);
  json.Key("status").String(partial ? "partial" : (run.ok ? "ok" : "failed"));
  json.Key("error").String(run.error);
  json.Key("order").BeginArray();
  for (const std::string& m : run.order) json.String(m);
  json.EndArray();
  json.Key("setups").BeginArray();
  for (const SetupRecord& r : run.setups) {
    json.BeginObject();
    json.Key("task_id").String(r.task_id);
    json.Key("mode").String(ModeName(r.mode));
    json.Key("order").Int(r.order);
    json.Key("target").Int(r.target);
    for (const auto& [key, id] : {std::pair{"start_id", &r.start_id}, std::pair{"target_id", &r.target_id}}) {
      json.Key(key);
      if (id->empty()) {
        json.Null();
      } else {
        json.String(*id);
      }
    }
    json.Key("start_deg").Array(r.start_deg);
    json.Key("target_deg").Array(r.target_deg);
    json.Key("reached_deg").Array(r.reached_deg);
    json.Key("assistant_reached_deg").Array(r.assistant_reached_deg);
    std::vector<double> error;
    for (size_t i = 0; i < r.reached_deg.size(); ++i)
      error.push_back(std::abs(r.reached_deg[i] - r.target_deg[i]));
    json.Key("error_deg").Array(error);
    json.Key("twisting").Array(r.twisting);
    json.Key("ranges").Array(r.ranges);
    json.Key("execution_s").Number(r.execution_s);
    json.Key("alignment_s").Number(r.alignment_s);
    json.Key("person_scale").Number(r.person_scale);
    json.Key("registration");
    if (r.mode == orbed::guidance_t::MODE_FIXED_DISPLAY) {
      json.Null();
    } else {
      json.String(r.perfect_registration ? "truth" : "measured");
    }
    json.Key("docking_tip_mm").Number(r.docking_tip_mm);
    json.Key("docking_axis_deg").Number(r.docking_axis_deg);
    json.Key("min_clearance_m").Number(r.min_clearance_m);
    json.Key("contact").Bool(r.contact);
    json.Key("collision_stops").Int(r.collision_stops);
    json.Key("alignment");
    if (r.alignment && r.alignment->mean) {
      json.BeginObject();
      json.Key("session_id").String(r.alignment->session_id);
      json.Key("trials").Int(static_cast<int64_t>(r.alignment->trials.size()));
      json.Key("translation_error_mm").Number(r.alignment->mean->errors.translation_error_mm);
      json.Key("rotation_error_deg").Number(r.alignment->mean->errors.rotation_error_deg);
      json.Key("misalignment_mm").Number(r.alignment->mean->errors.misalignment_mm);
      json.EndObject();
    } else {
      json.Null();
    }
    json.EndObject();
  }
  json.EndArray();
  json.EndObject();
  return json.str() + "\n";
}

namespace {

constexpr size_t kMaxSetupResultsBytes = 4 << 20;
constexpr int kMaxSetupResultsDepth = 6;
constexpr size_t kMaxText = 4096;
constexpr size_t kMaxSetups = 1000;
constexpr size_t kMaxJoints = 64;

std::vector<int> Integers(const JsonFields& f, const JsonAt& at, int64_t lo, int64_t hi) {
  std::vector<int> out;
  for (size_t k = 0, n = f.ArraySize(at, kMaxJoints); k < n; ++k)
    out.push_back(static_cast<int>(f.Integer(f.Element(at, k), lo, hi)));
  return out;
}

std::vector<double> Degrees(const JsonFields& f, const JsonAt& at) {
  return f.Numbers(at, f.ArraySize(at, kMaxJoints), -1e4, 1e4);
}

int8_t ModeNamed(const JsonFields& f, const JsonAt& at) {
  const std::string name = f.String(at, 64);
  try {
    return guidance::GuidanceModeFromName(name);
  } catch (const std::invalid_argument&) {
    f.Fail(at.key, "ar, ar_reflective or fixed", &at.value);
  }
}

// The document's fields (ReadSetupRunFile, ParseSetupRunJson).
SetupRun SetupRunFromJson(const JsonFields& f, const nlohmann::json& doc, std::string* status);

}  // namespace

SetupRun ReadSetupRunFile(const std::string& path, std::string* status) {
  std::string file = path;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    file = (std::filesystem::path(path) / "setup_results.json").string();
  const JsonFields f(file);
  return SetupRunFromJson(f, f.ReadFile(file, kMaxSetupResultsBytes, kMaxSetupResultsDepth), status);
}

SetupRun ParseSetupRunJson(const std::string& text, const std::string& source, std::string* status) {
  const JsonFields f(source);
  return SetupRunFromJson(f, f.Parse(text, kMaxSetupResultsBytes, kMaxSetupResultsDepth), status);
}

namespace {

SetupRun SetupRunFromJson(const JsonFields& f, const nlohmann::json& doc, std::string* status) {
  const JsonAt root{doc, ""};
  SetupRun run;
  run.user = f.String(f.Member(root, "user"), 256);
  run.run_id = f.String(f.Member(root, "run_id"), 256);
  if (const auto record = f.OptionalMember(root, "provenance")) run.provenance = f.String(*record, 256);
  const JsonAt status_at = f.Member(root, "status");
  *status = f.String(status_at, 16);
  if (*status != "ok" && *status != "failed" && *status != "partial")
    f.Fail(status_at.key, "\"ok\", \"failed\" or \"partial\"", &status_at.value);
  run.ok = *status == "ok";
  run.error = f.String(f.Member(root, "error"), kMaxText);
  const JsonAt order = f.Member(root, "order");
  for (size_t k = 0, n = f.ArraySize(order, 3); k < n; ++k)
    run.order.push_back(ModeName(ModeNamed(f, f.Element(order, k))));
  const JsonAt setups = f.Member(root, "setups");
  for (size_t k = 0, n = f.ArraySize(setups, kMaxSetups); k < n; ++k) {
    const JsonAt at = f.Element(setups, k);
    SetupRecord r;
    r.task_id = f.String(f.Member(at, "task_id"), 256);
    r.mode = ModeNamed(f, f.Member(at, "mode"));
    r.order = static_cast<int>(f.Integer(f.Member(at, "order"), 1, 3));
    r.target = static_cast<int>(f.Integer(f.Member(at, "target"), 1, 1000));
    if (const auto id = f.OptionalMember(at, "start_id")) r.start_id = f.String(*id, 256);
    if (const auto id = f.OptionalMember(at, "target_id")) r.target_id = f.String(*id, 256);
    if (const auto q = f.OptionalMember(at, "start_deg")) r.start_deg = Degrees(f, *q);
    r.target_deg = Degrees(f, f.Member(at, "target_deg"));
    r.reached_deg = Degrees(f, f.Member(at, "reached_deg"));
    r.assistant_reached_deg = Degrees(f, f.Member(at, "assistant_reached_deg"));
    if (r.reached_deg.size() != r.target_deg.size() || r.assistant_reached_deg.size() != r.target_deg.size())
      f.Fail(at.key + ".reached_deg", "as many joints as target_deg");
    r.twisting = Integers(f, f.Member(at, "twisting"), 0, 1);
    r.ranges = Integers(f, f.Member(at, "ranges"), 0, 1000);
    r.execution_s = f.Number(f.Member(at, "execution_s"), 0, 1e7);
    if (const auto a = f.OptionalMember(at, "alignment_s")) r.alignment_s = f.Number(*a, 0, 1e7);
    r.person_scale = f.Number(f.Member(at, "person_scale"), 1e-3, 1e3);
    if (const auto reg = f.OptionalMember(at, "registration")) {
      const std::string text = f.String(*reg, 16);
      if (text != "measured" && text != "truth")
        f.Fail(reg->key, "\"measured\", \"truth\" or null", &reg->value);
      r.perfect_registration = text == "truth";
    }
    r.docking_tip_mm = f.Number(f.Member(at, "docking_tip_mm"), 0, 1e7);
    r.docking_axis_deg = f.Number(f.Member(at, "docking_axis_deg"), 0, 180);
    if (const auto c = f.OptionalMember(at, "min_clearance_m")) r.min_clearance_m = f.Number(*c, -100, 100);
    r.contact = f.Bool(f.Member(at, "contact"));
    r.collision_stops = static_cast<int>(f.Integer(f.Member(at, "collision_stops"), 0, 1 << 30));
    if (const auto a = f.OptionalMember(at, "alignment")) {
      viraal::SessionResult session;
      session.session_id = f.String(f.Member(*a, "session_id"), 256);
      session.trials.resize(static_cast<size_t>(f.Integer(f.Member(*a, "trials"), 0, 1000)));
      viraal::MeanResult mean;
      mean.errors.translation_error_mm = f.Number(f.Member(*a, "translation_error_mm"), 0, 1e9);
      mean.errors.rotation_error_deg = f.Number(f.Member(*a, "rotation_error_deg"), 0, 180);
      mean.errors.misalignment_mm = f.Number(f.Member(*a, "misalignment_mm"), 0, 1e9);
      session.mean = mean;
      r.alignment = session;
    }
    run.setups.push_back(std::move(r));
  }
  return run;
}

}  // namespace

std::vector<SetupRecord> KeptSetups(const SetupRun& earlier, const std::string& status,
                                    const SetupOptions& options) {
  auto refuse = [](const std::string& why) { throw std::invalid_argument("cannot resume: " + why); };
  if (status == "ok") refuse("that run finished (status ok): nothing is left to run");
  if (earlier.user != options.user)
    refuse("it is user " + earlier.user + "'s, this run is " + options.user + "'s");
  if (earlier.run_id != options.run_id)
    refuse("its run id is " + earlier.run_id + ", this run's " + options.run_id);
  std::vector<std::string> order;
  for (int8_t m : options.modes) order.push_back(ModeName(m));
  if (earlier.order != order) refuse("its order of the modes is not this run's");
  const size_t total = options.modes.size() * options.targets_deg.size();
  if (earlier.setups.size() >= total) {
    refuse("it holds " + std::to_string(earlier.setups.size()) + " set-ups, this run has " +
           std::to_string(total) + ": nothing is left to run");
  }
  for (size_t i = 0; i < earlier.setups.size(); ++i) {
    const SetupRecord& r = earlier.setups[i];
    const size_t mode_index = i / options.targets_deg.size(), target_index = i % options.targets_deg.size();
    const int8_t mode = options.modes[mode_index];
    const std::string task_id = options.user + "-" + ModeName(mode) + "-" + std::to_string(target_index + 1);
    if (r.task_id != task_id || r.mode != mode || r.order != static_cast<int>(mode_index) + 1 ||
        r.target != static_cast<int>(target_index) + 1) {
      refuse("set-up " + std::to_string(i + 1) + " is " + r.task_id + ", this run's is " + task_id);
    }
    const std::vector<double>& target = options.targets_deg[target_index];
    bool same = r.target_deg.size() == target.size();
    for (size_t j = 0; same && j < target.size(); ++j) same = std::abs(r.target_deg[j] - target[j]) <= 1e-9;
    if (!same) refuse(task_id + "'s target is not this plan's target " + std::to_string(target_index + 1));
    const std::vector<double>& start =
        options.starts_deg.empty() ? options.start_deg : options.starts_deg[target_index];
    bool same_start = r.start_deg.empty() || r.start_deg.size() == start.size();
    for (size_t j = 0; same_start && j < r.start_deg.size(); ++j)
      same_start = std::abs(r.start_deg[j] - start[j]) <= 1e-9;
    const std::string start_id = options.start_ids.empty() ? "" : options.start_ids[target_index];
    const std::string target_id = options.target_ids.empty() ? "" : options.target_ids[target_index];
    if (!same_start || (!r.start_deg.empty() && (r.start_id != start_id || r.target_id != target_id)))
      refuse(task_id + "'s start or design ids are not this run's (another --design or user seed?)");
    const bool truth = options.perfect_registration && mode != orbed::guidance_t::MODE_FIXED_DISPLAY;
    if (r.perfect_registration != truth)
      refuse(task_id + " was made with another registration (--registration)");
  }
  return earlier.setups;
}

SetupConductor::SetupConductor(SetupOptions options, sim::RobotModel model)
    : options_(std::move(options)), model_(std::make_unique<const sim::RobotModel>(std::move(model))) {
  if (options_.modes.empty()) throw std::invalid_argument("set-up study: no modes");
  for (size_t i = 0; i < options_.modes.size(); ++i) {
    if (options_.modes[i] < 0 || options_.modes[i] > 2)
      throw std::invalid_argument("set-up study: mode out of range");
    for (size_t j = 0; j < i; ++j) {
      if (options_.modes[j] == options_.modes[i]) {
        throw std::invalid_argument("set-up study: mode " + ModeName(options_.modes[i]) + " twice");
      }
    }
  }
  if (options_.targets_deg.empty()) throw std::invalid_argument("set-up study: no targets");
  auto check = [&](const std::vector<double>& q_deg, const std::string& what) {
    if (static_cast<int>(q_deg.size()) != model_->num_joints()) {
      throw std::invalid_argument("set-up study: " + what + " has " + std::to_string(q_deg.size()) +
                                  " joints, the robot " + std::to_string(model_->num_joints()));
    }
    Eigen::VectorXd q(q_deg.size());
    for (size_t i = 0; i < q_deg.size(); ++i) q[i] = q_deg[i] * kDegToRad;
    const std::string limits = model_->ValidateJointVector(q);
    if (!limits.empty()) throw std::invalid_argument("set-up study: " + what + ": " + limits);
  };
  for (size_t k = 0; k < options_.targets_deg.size(); ++k)
    check(options_.targets_deg[k], "target " + std::to_string(k + 1));
  const size_t n = options_.targets_deg.size();
  if ((!options_.starts_deg.empty() && options_.starts_deg.size() != n) ||
      (!options_.start_ids.empty() && options_.start_ids.size() != n) ||
      (!options_.target_ids.empty() && options_.target_ids.size() != n)) {
    throw std::invalid_argument("set-up study: per-target starts and ids must be one per target");
  }
  if (options_.starts_deg.empty()) check(options_.start_deg, "the start");
  for (size_t k = 0; k < options_.starts_deg.size(); ++k)
    check(options_.starts_deg[k], "the start of target " + std::to_string(k + 1));
  for (int8_t kind : guidance::JointKinds(*model_))
    twisting_.push_back(kind == orbed::guidance_t::JOINT_TWIST);
  if (options_.retract && !options_.retract_scene_path.empty()) {
    retract_scene_ = std::make_unique<sim::Scene>(sim::LoadSceneFile(options_.retract_scene_path));
    retract_world_ = std::make_unique<sim::CollisionWorld>(*model_, retract_scene_.get());
  }
  run_.user = options_.user;
  run_.run_id = options_.run_id;
  for (int8_t m : options_.modes) run_.order.push_back(ModeName(m));
  if (options_.kept.size() >= options_.modes.size() * options_.targets_deg.size())
    throw std::invalid_argument("set-up study: the kept set-ups leave nothing to run");
  run_.setups = options_.kept;
  mode_index_ = options_.kept.size() / options_.targets_deg.size();
  target_index_ = options_.kept.size() % options_.targets_deg.size();
}

SetupConductor::~SetupConductor() = default;

void SetupConductor::Begin(const ConductorTime& now) {
  if (phase_ == Phase::kNotStarted) throw std::logic_error("SetupConductor: Start() first");
  now_ = now;
}

SetupConductor::Actions SetupConductor::Take() {
  Actions out = std::move(actions_);
  actions_ = Actions{};
  return out;
}

std::string SetupConductor::TaskId() const {
  return options_.user + "-" + ModeName(Mode()) + "-" + std::to_string(target_index_ + 1);
}

SetupConductor::Actions SetupConductor::Start(const ConductorTime& now) {
  if (phase_ != Phase::kNotStarted) throw std::logic_error("SetupConductor: Start() twice");
  now_ = now;
  request_id_base_ = now.utime;
  phase_ = Phase::kWaitRobot;
  phase_start_s_ = now.t_s;
  std::string order;
  for (const std::string& m : run_.order) order += (order.empty() ? "" : ", ") + m;
  actions_.progress.push_back("set-up study, user " + options_.user + ": modes " + order + ", " +
                              std::to_string(options_.targets_deg.size()) + " target(s) each" +
                              (options_.kept.empty()
                                   ? ""
                                   : "; resumed with the " + std::to_string(options_.kept.size()) +
                                         " set-up(s) kept, next " + TaskId()));
  return Take();
}

const std::vector<double>& SetupConductor::StartDeg() const {
  return options_.starts_deg.empty() ? options_.start_deg : options_.starts_deg[target_index_];
}

void SetupConductor::StartTask() {
  alignment_result_.reset();
  if (Mode() == orbed::guidance_t::MODE_FIXED_DISPLAY || options_.perfect_registration) return EnterPark();
  scenario::ConductorOptions o;
  o.config = options_.alignment;
  const bool reflective = Mode() == orbed::guidance_t::MODE_AR_REFLECTIVE;
  o.config.modes = {viraal::ModeFromName(reflective ? "ar_reflective" : "ar", options_.reflective_mirrors)};
  o.run_id = options_.run_id + "-" + TaskId();
  o.startup_timeout_s = options_.startup_timeout_s;
  o.move_timeout_s = options_.move_timeout_s;
  o.request_deadline_s = options_.request_deadline_s;
  alignment_ = std::make_unique<scenario::ViraalConductor>(o, *model_);
  phase_ = Phase::kAlign;
  phase_start_s_ = now_.t_s;
  actions_.progress.push_back(TaskId() + ": aligning " + std::to_string(o.config.trials) + " times (" +
                              ModeName(Mode()) + ")");
  ConductorActions started = alignment_->Start(now_);
  actions_.viraal.insert(actions_.viraal.end(), started.begin(), started.end());
  // The conductor waits for a ROBOT_STATE: give it the latest at once.
  if (robot_state_) {
    ConductorActions more = alignment_->OnRobotState(*robot_state_, now_);
    actions_.viraal.insert(actions_.viraal.end(), more.begin(), more.end());
  }
}

void SetupConductor::EnterRetract() {
  std::vector<double> q;
  for (double v : robot_state_->joint_position) q.push_back(v * kRadToDeg);
  // Whether the sim would let the arm move straight from a to b (see the file comment).
  const auto passes = [this](const std::vector<double>& a, const std::vector<double>& b) {
    if (!retract_world_) return true;
    double travel = 0;
    for (size_t i = 0; i < a.size(); ++i) travel = std::max(travel, std::abs(b[i] - a[i]));
    const int n = std::max(1, static_cast<int>(std::ceil(travel / 2.0)));
    double before = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= n; ++k) {
      Eigen::VectorXd x(a.size());
      for (size_t i = 0; i < a.size(); ++i) x[i] = (a[i] + (b[i] - a[i]) * k / n) * kDegToRad;
      const double d = retract_world_->Check(x).min_distance_m;
      if (k > 0 && d < 0.01 && d < before) return false;
      before = d;
    }
    return true;
  };
  retract_route_.clear();
  std::vector<size_t> left;
  for (size_t j : {3, 1, 5, 0}) {
    if (j < q.size()) left.push_back(j);
  }
  while (!left.empty()) {
    size_t pick = 0;
    for (size_t i = 0; i < left.size(); ++i) {
      std::vector<double> next = q;
      next[left[i]] = 0;
      if (passes(q, next)) {
        pick = i;
        break;
      }
    }
    q[left[pick]] = 0;
    left.erase(left.begin() + static_cast<std::ptrdiff_t>(pick));
    retract_route_.push_back(q);
  }
  retract_route_.push_back(std::vector<double>(q.size(), 0.0));
  phase_ = Phase::kRetract;
  phase_start_s_ = now_.t_s;
  last_send_s_ = -1e9;
  Step();
}

bool SetupConductor::MoveTo(const std::vector<double>& q_deg, const std::string& what) {
  bool there = robot_state_ && robot_state_->motion_state == orbed::robot_state_t::MOTION_IDLE;
  for (size_t i = 0; there && i < q_deg.size(); ++i)
    there = std::abs(robot_state_->joint_position[i] * kRadToDeg - q_deg[i]) < options_.tolerance_deg;
  if (there) return true;
  if (now_.t_s - phase_start_s_ > options_.move_timeout_s) {
    Fail(TaskId() + ": the arm did not reach " + what + " within " + Fixed(options_.move_timeout_s, 1) +
         " s (orbed-iiwa-sim)");
    return false;
  }
  if (now_.t_s - last_send_s_ >= options_.command_resend_s) {
    orbed::iiwa_command_t command{};
    command.utime = now_.utime;
    command.num_joints = model_->num_joints();
    for (double q : q_deg) command.joint_position.push_back(q * kDegToRad);
    command.num_torques = 0;
    actions_.publish.push_back({options_.iiwa_command_channel, command});
    last_send_s_ = now_.t_s;
  }
  return false;
}

void SetupConductor::EnterPark() {
  phase_ = Phase::kPark;
  phase_start_s_ = now_.t_s;
  last_send_s_ = -1e9;
  Step();
}

void SetupConductor::SendTask() {
  if (options_.perfect_registration && Mode() != orbed::guidance_t::MODE_FIXED_DISPLAY) {
    orbed::registration_t truth{};
    truth.utime = now_.utime;
    truth.session_id = options_.run_id + "-" + task_.task_id + "-truth";
    truth.reason = orbed::registration_t::REASON_COMPUTE;
    truth.valid = true;
    truth.X_WV_mean = robot_state_->X_WR;  // kPark waited for a ROBOT_STATE
    truth.converged = true;
    truth.unique = true;
    actions_.publish.push_back({options_.registration_channel, truth});
  }
  actions_.publish.push_back({options_.setup_task_channel, task_});
  last_send_s_ = now_.t_s;
}

void SetupConductor::Fail(const std::string& reason) {
  run_.ok = false;
  run_.error = reason;
  phase_ = Phase::kDone;
  actions_.progress.push_back("FAILED: " + reason);
}

void SetupConductor::Step() {
  switch (phase_) {
    case Phase::kNotStarted:
    case Phase::kDone:
      return;
    case Phase::kWaitRobot:
      if (robot_state_) return StartTask();
      if (now_.t_s - phase_start_s_ > options_.startup_timeout_s) {
        Fail("no ROBOT_STATE within " + Fixed(options_.startup_timeout_s, 1) +
             " s: is orbed-iiwa-sim running?");
      }
      return;
    case Phase::kAlign: {
      if (!alignment_->done()) return;
      if (alignment_->status() != scenario::ViraalConductor::Status::kSucceeded) {
        return Fail(TaskId() + ": the alignment failed: " + alignment_->results().error);
      }
      alignment_result_ = alignment_->results().sessions.back();
      alignment_.reset();
      return EnterPark();
    }
    case Phase::kRetract: {
      // A waypoint the sim stops short of (before a collision) is passed over for the next one,
      // after kRetryAfterStopS (so that a state from before the command does not count); the
      // last, the candle, is not.
      constexpr double kRetryAfterStopS = 0.5;
      const bool blocked = robot_state_ && Stopped(robot_state_->motion_state) &&
                           now_.t_s - phase_start_s_ >= kRetryAfterStopS && retract_route_.size() > 1;
      if (!blocked &&
          !MoveTo(retract_route_.front(), retract_route_.size() > 1 ? "the straightened arm" : "the candle"))
        return;
      retract_route_.erase(retract_route_.begin());
      phase_start_s_ = now_.t_s;
      last_send_s_ = -1e9;
      if (retract_route_.empty()) return StartTask();
      return Step();
    }
    case Phase::kPark: {
      if (!MoveTo(StartDeg(), "the start")) return;
      task_ = orbed::setup_task_t{};
      task_.utime = now_.utime;
      task_.request_id = request_id_base_ + next_request_id_++;
      task_.task_id = TaskId();
      task_.mode = Mode();
      task_.num_joints = model_->num_joints();
      for (double q : options_.targets_deg[target_index_]) task_.target_position.push_back(q * kDegToRad);
      phase_ = Phase::kTask;
      phase_start_s_ = now_.t_s;
      task_min_clearance_m_.reset();
      task_contact_ = false;
      task_collision_stops_ = 0;
      actions_.progress.push_back(TaskId() + ": set-up (SETUP_TASK to orbed-assistant)");
      return SendTask();
    }
    case Phase::kTask:
      if (now_.t_s - phase_start_s_ > options_.task_timeout_s) {
        if (pending_result_) {
          return Fail(TaskId() +
                      ": SETUP_RESULT came but no ROBOT_STATE with the arm at rest followed within " +
                      Fixed(options_.task_timeout_s, 1) + " s: is orbed-iiwa-sim running?");
        }
        return Fail(TaskId() + ": no SETUP_RESULT within " + Fixed(options_.task_timeout_s, 1) +
                    " s: is orbed-assistant running (and orbed-guidance)?");
      }
      if (!pending_result_ && now_.t_s - last_send_s_ >= options_.task_resend_s) SendTask();
      return;
  }
}

SetupConductor::Actions SetupConductor::OnRobotState(const orbed::robot_state_t& msg,
                                                     const ConductorTime& now) {
  Begin(now);
  const std::string problem = CheckRobotState(msg, model_->num_joints());
  if (!problem.empty()) {
    actions_.refusals.push_back({options_.robot_state_channel + "/field", problem});
    return Take();
  }
  if (phase_ == Phase::kTask) {
    const bool was_stopped =
        robot_state_ && Stopped(robot_state_->motion_state) && robot_state_->motion_state == msg.motion_state;
    if (Stopped(msg.motion_state) && !was_stopped) ++task_collision_stops_;
    if (msg.motion_state == orbed::robot_state_t::MOTION_IN_COLLISION) task_contact_ = true;
  }
  robot_state_ = msg;
  if (phase_ == Phase::kTask && pending_result_ && msg.motion_state != orbed::robot_state_t::MOTION_MOVING) {
    const orbed::setup_result_t result = *pending_result_;
    pending_result_.reset();
    Record(result);
    return Take();
  }
  if (phase_ == Phase::kAlign) {
    ConductorActions more = alignment_->OnRobotState(msg, now);
    actions_.viraal.insert(actions_.viraal.end(), more.begin(), more.end());
  }
  Step();
  return Take();
}

#define ORBED_FORWARD(Method, Type)                                                           \
  SetupConductor::Actions SetupConductor::Method(const Type& msg, const ConductorTime& now) { \
    Begin(now);                                                                               \
    if (phase_ == Phase::kAlign) {                                                            \
      ConductorActions more = alignment_->Method(msg, now);                                   \
      actions_.viraal.insert(actions_.viraal.end(), more.begin(), more.end());                \
      Step();                                                                                 \
    }                                                                                         \
    return Take();                                                                            \
  }
ORBED_FORWARD(OnPlanCheckReply, orbed::plan_check_reply_t)
ORBED_FORWARD(OnTrial, orbed::alignment_trial_t)
ORBED_FORWARD(OnRegistration, orbed::registration_t)
ORBED_FORWARD(OnLandmark, orbed::landmark_t)
ORBED_FORWARD(OnMisalignment, orbed::misalignment_t)
#undef ORBED_FORWARD

SetupConductor::Actions SetupConductor::OnSetupResult(const orbed::setup_result_t& msg,
                                                      const ConductorTime& now) {
  Begin(now);
  if (phase_ != Phase::kTask || msg.request_id != task_.request_id) return Take();  // not ours, or a repeat
  const std::string problem = guidance::CheckSetupResult(msg, *model_, 0.01);
  if (!problem.empty()) {
    actions_.refusals.push_back({options_.setup_result_channel + "/field", problem});
    return Take();
  }
  // The arm's joints are recorded from the first ROBOT_STATE handled after this answer with the
  // arm not moving: the last one handled before it may predate the assistant's final reading.
  if (!pending_result_) pending_result_ = msg;
  return Take();
}

void SetupConductor::Record(const orbed::setup_result_t& msg) {
  SetupRecord r;
  r.task_id = task_.task_id;
  r.mode = Mode();
  r.order = static_cast<int>(mode_index_) + 1;
  r.target = static_cast<int>(target_index_) + 1;
  r.target_deg = options_.targets_deg[target_index_];
  r.start_deg = StartDeg();
  if (!options_.start_ids.empty()) r.start_id = options_.start_ids[target_index_];
  if (!options_.target_ids.empty()) r.target_id = options_.target_ids[target_index_];
  for (double q : robot_state_->joint_position) r.reached_deg.push_back(q * kRadToDeg);
  for (double q : msg.reached_position) r.assistant_reached_deg.push_back(q * kRadToDeg);
  r.twisting = twisting_;
  r.ranges.assign(msg.ranges.begin(), msg.ranges.end());
  r.execution_s = msg.execution_s;
  r.person_scale = msg.person_scale;
  r.perfect_registration = options_.perfect_registration && r.mode != orbed::guidance_t::MODE_FIXED_DISPLAY;
  const Docking docking = DockingError(*model_, r.target_deg, r.reached_deg);
  r.docking_tip_mm = docking.tip_mm;
  r.docking_axis_deg = docking.axis_deg;
  r.min_clearance_m = task_min_clearance_m_;
  r.contact = task_contact_;
  r.collision_stops = task_collision_stops_;
  if (alignment_result_) {
    double total = 0;
    for (const viraal::TrialResult& t : alignment_result_->trials) total += t.user_duration_s;
    r.alignment_s = total;
    r.alignment = alignment_result_;
  }
  double worst = 0;
  for (size_t i = 0; i < r.reached_deg.size(); ++i)
    worst = std::max(worst, std::abs(r.reached_deg[i] - r.target_deg[i]));
  actions_.progress.push_back(r.task_id + ": done, largest joint error " + Fixed(worst, 1) +
                              " deg, docking " + Fixed(r.docking_tip_mm, 0) + " mm / " +
                              Fixed(r.docking_axis_deg, 1) + " deg, execution " + Fixed(r.execution_s, 0) +
                              " s");
  run_.setups.push_back(std::move(r));
  if (++target_index_ >= options_.targets_deg.size()) {
    target_index_ = 0;
    ++mode_index_;
  }
  if (mode_index_ >= options_.modes.size()) {
    run_.ok = true;
    phase_ = Phase::kDone;
    return;
  }
  if (options_.retract) return EnterRetract();
  StartTask();
}

SetupConductor::Actions SetupConductor::OnCollisionStatus(const orbed::collision_status_t& msg,
                                                          const ConductorTime& now) {
  Begin(now);
  const std::string problem = CheckCollisionStatus(msg);
  if (!problem.empty()) {
    actions_.refusals.push_back({options_.collision_status_channel + "/field", problem});
    return Take();
  }
  if (phase_ == Phase::kTask) {
    task_min_clearance_m_ = std::min(task_min_clearance_m_.value_or(msg.min_distance_m), msg.min_distance_m);
    if (msg.in_collision) task_contact_ = true;
  }
  return Take();
}

SetupConductor::Actions SetupConductor::Tick(const ConductorTime& now) {
  Begin(now);
  if (phase_ == Phase::kAlign) {
    ConductorActions more = alignment_->Tick(now);
    actions_.viraal.insert(actions_.viraal.end(), more.begin(), more.end());
  }
  Step();
  return Take();
}

SetupConductor::Actions SetupConductor::Abort(const std::string& reason, const ConductorTime& now) {
  Begin(now);
  if (phase_ != Phase::kDone) Fail(reason);
  return Take();
}

std::vector<int8_t> ModeOrderForSeed(uint64_t user_seed) {
  std::vector<int8_t> order = {0, 1, 2};
  Random rng(user_seed ^ 0x5e7a9ULL);
  for (int i = 2; i > 0; --i) {
    const int j = static_cast<int>(rng.Uniform() * (i + 1));
    std::swap(order[i], order[j]);
  }
  return order;
}

std::vector<int8_t> ModeOrderFromNames(const std::string& names) {
  std::vector<int8_t> modes;
  size_t begin = 0;
  while (begin <= names.size()) {
    const size_t comma = std::min(names.find(',', begin), names.size());
    modes.push_back(guidance::GuidanceModeFromName(names.substr(begin, comma - begin)));
    begin = comma + 1;
  }
  return modes;
}

std::vector<std::vector<double>> PlanTargetsDeg(const std::string& plan_path, int count,
                                                const sim::RobotModel& model) {
  std::vector<std::vector<double>> targets;
  for (int k = 1; k <= count; ++k) {
    const Eigen::VectorXd q = guidance::ReadPlanTarget(plan_path, k, model.num_joints()) * kRadToDeg;
    targets.emplace_back(q.data(), q.data() + q.size());
  }
  return targets;
}

}  // namespace orbed::setup
