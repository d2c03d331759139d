#include "procs/assistant/assistant.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <orbed/guidance_t.hpp>

#include "base/hash.h"
#include "base/units.h"
#include "base/yaml_fields.h"

namespace orbed::assistant {
namespace {

constexpr double kArcminToRad = kDegToRad / 60.0;
// Tags the pace's random stream apart from the person's main one (any constant; changing it changes
// every person's pace).
constexpr std::uint64_t kPaceStreamTag = 0x70616365;  // "pace"

// Two unit vectors across the unit ray n.
void Across(const Eigen::Vector3d& n, Eigen::Vector3d* e1, Eigen::Vector3d* e2) {
  const Eigen::Vector3d helper = std::abs(n.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  *e1 = n.cross(helper).normalized();
  *e2 = n.cross(*e1);
}

// A point seen from `origin` with noise: `lateral_rad` across the ray (two axes), `depth_fraction`
// of the distance along it.
Eigen::Vector3d Perturb(const Eigen::Vector3d& p, const Eigen::Vector3d& origin, double lateral_rad,
                        double depth_fraction, Random* rng) {
  const double rho = (p - origin).norm();
  const Eigen::Vector3d n = (p - origin) / rho;
  Eigen::Vector3d e1, e2;
  Across(n, &e1, &e2);
  const double a = rng->Normal(), b = rng->Normal(), c = rng->Normal();
  return p + rho * lateral_rad * (a * e1 + b * e2) + rho * depth_fraction * c * n;
}

void AddUnique(int link, const Eigen::Vector3d& p_L, std::vector<Feature>* features) {
  for (const Feature& f : *features) {
    if (f.link == link && (f.p_L - p_L).norm() < 1e-3) return;
  }
  features->push_back({link, p_L});
}

// The skeleton of the links of `body` (file comment of assistant.h).
void AddBody(const sim::RobotModel& model, int body, double marker_m, std::vector<Feature>* features) {
  for (int i = 0; i < model.num_links(); ++i) {
    const sim::RobotLink& link = model.links()[i];
    if (link.body != body) continue;
    AddUnique(i, Eigen::Vector3d::Zero(), features);
    for (const sim::CollisionPrimitive& g : link.collision) {
      AddUnique(i, g.X_LG.translation(), features);
      if (g.kind == sim::CollisionPrimitive::Kind::kCylinder ||
          g.kind == sim::CollisionPrimitive::Kind::kCapsule) {
        const Eigen::Vector3d half = 0.5 * g.length_m * g.X_LG.linear().col(2);
        AddUnique(i, g.X_LG.translation() + half, features);
        AddUnique(i, g.X_LG.translation() - half, features);
      } else if (g.kind == sim::CollisionPrimitive::Kind::kBox) {
        for (int c = 0; c < 8; ++c) {
          const Eigen::Vector3d corner(((c & 1) ? 0.5 : -0.5) * g.size_m.x(),
                                       ((c & 2) ? 0.5 : -0.5) * g.size_m.y(),
                                       ((c & 4) ? 0.5 : -0.5) * g.size_m.z());
          AddUnique(i, g.X_LG * corner, features);
        }
      }
    }
    if (i == model.flange_link() && marker_m > 0) AddUnique(i, Eigen::Vector3d(marker_m, 0, 0), features);
  }
}

void CheckConfig(const AssistantConfig& c) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("assistant config: ") + what);
  };
  require(c.eye_position_m.allFinite() && c.monitor_camera_m.allFinite() && c.display_capture_m.allFinite(),
          "positions must be finite");
  require(c.lateral_noise_arcmin > 0 && c.depth_noise_fraction_std > 0 && c.picture_noise_arcmin > 0 &&
              c.picture_depth_fraction_std > 0 && c.display_noise_arcmin > 0 &&
              c.display_depth_fraction_std > 0,
          "perception noises must be > 0");
  require(c.user_scale_log_sigma >= 0 && c.rotation_error_base_deg >= 0 && c.rotation_error_per_deg >= 0 &&
              c.picture_scale_log_sigma >= 0 && c.placement_noise_deg >= 0 && c.flange_marker_offset_m >= 0,
          "spreads must be >= 0");
  require(c.turn_view_leaves_deg >= 0 && c.turn_view_leaves_deg <= c.turn_view_above_deg &&
              c.turn_view_above_deg <= 180,
          "0 <= turn_view_leaves_deg <= turn_view_above_deg <= 180");
  require(
      c.match_margin > 0 && c.looks_per_joint >= 1 && c.looks_per_joint <= 10 && c.correction_window_deg > 0,
      "match_margin > 0, looks_per_joint 1..10, correction_window_deg > 0");
  require(c.joint_overhead_s >= 0 && c.look_s >= 0 && c.mental_rotation_deg_per_s > 0 &&
              c.hand_speed_deg_per_s > 0 && c.view_turn_deg_per_s > 0 && c.view_zoom_s >= 0 &&
              c.display_consult_s >= 0 && c.pace_log_sigma >= 0 && c.pace_log_sigma <= 2,
          "times >= 0, speeds > 0, pace_log_sigma 0..2");
}

// The weighted squared distance d^T W d of the file comment, W from the ray origin -> r.
double WeightedSquare(const Eigen::Vector3d& d, const Eigen::Vector3d& r, const Eigen::Vector3d& origin,
                      double lateral_rad, double depth_fraction) {
  const double rho = std::max((r - origin).norm(), 0.05);
  const Eigen::Vector3d n = (r - origin) / rho;
  const double along = n.dot(d);
  const double across2 = (d - along * n).squaredNorm();
  return across2 / std::pow(rho * lateral_rad, 2) + along * along / std::pow(rho * depth_fraction, 2);
}

}  // namespace

AssistantConfig LoadAssistantConfig(const std::string& path) {
  const YAML::Node root = YamlFields::LoadFile(path);
  const YamlFields f(path);
  f.CheckKeys(root, "", {"assistant"});
  const YAML::Node a = f.Required(root, "assistant", "assistant");
  f.CheckKeys(a, "assistant",
              {"seed", "eye_position_m", "user_scale_log_sigma", "headset", "reflective", "monitor", "acting",
               "time"});
  AssistantConfig c;
  c.seed = static_cast<uint64_t>(f.IntegerOr(a, "seed", "assistant", 1, 0, 1'000'000'000));
  if (a["eye_position_m"]) c.eye_position_m = f.Vector3(a["eye_position_m"], "assistant.eye_position_m", "m");
  c.user_scale_log_sigma = f.NumberOr(a, "user_scale_log_sigma", "assistant", c.user_scale_log_sigma, 0, 2);

  const YAML::Node h = f.Section(a, "headset", "assistant.headset");
  f.CheckKeys(h, "assistant.headset", {"lateral_noise_arcmin", "depth_noise_fraction_std"});
  c.lateral_noise_arcmin =
      f.NumberOr(h, "lateral_noise_arcmin", "assistant.headset", c.lateral_noise_arcmin, 1e-3, 600, "arcmin");
  c.depth_noise_fraction_std =
      f.NumberOr(h, "depth_noise_fraction_std", "assistant.headset", c.depth_noise_fraction_std, 1e-5, 1);

  const YAML::Node r = f.Section(a, "reflective", "assistant.reflective");
  f.CheckKeys(r, "assistant.reflective", {"capture_m", "noise_arcmin", "depth_fraction_std", "consult_s"});
  if (r["capture_m"]) c.display_capture_m = f.Vector3(r["capture_m"], "assistant.reflective.capture_m", "m");
  c.display_noise_arcmin =
      f.NumberOr(r, "noise_arcmin", "assistant.reflective", c.display_noise_arcmin, 1e-3, 600, "arcmin");
  c.display_depth_fraction_std =
      f.NumberOr(r, "depth_fraction_std", "assistant.reflective", c.display_depth_fraction_std, 1e-5, 1);
  c.display_consult_s = f.NumberOr(r, "consult_s", "assistant.reflective", c.display_consult_s, 0, 600, "s");

  const YAML::Node m = f.Section(a, "monitor", "assistant.monitor");
  f.CheckKeys(m, "assistant.monitor",
              {"camera_m", "rotation_error_base_deg", "rotation_error_per_deg", "picture_scale_log_sigma",
               "picture_noise_arcmin", "picture_depth_fraction_std", "turn_view_above_deg",
               "turn_view_leaves_deg", "view_turn_deg_per_s", "view_zoom_s"});
  if (m["camera_m"]) c.monitor_camera_m = f.Vector3(m["camera_m"], "assistant.monitor.camera_m", "m");
  c.rotation_error_base_deg =
      f.NumberOr(m, "rotation_error_base_deg", "assistant.monitor", c.rotation_error_base_deg, 0, 90, "deg");
  c.rotation_error_per_deg =
      f.NumberOr(m, "rotation_error_per_deg", "assistant.monitor", c.rotation_error_per_deg, 0, 2, "deg/deg");
  c.picture_scale_log_sigma =
      f.NumberOr(m, "picture_scale_log_sigma", "assistant.monitor", c.picture_scale_log_sigma, 0, 1);
  c.picture_noise_arcmin =
      f.NumberOr(m, "picture_noise_arcmin", "assistant.monitor", c.picture_noise_arcmin, 1e-3, 600, "arcmin");
  c.picture_depth_fraction_std =
      f.NumberOr(m, "picture_depth_fraction_std", "assistant.monitor", c.picture_depth_fraction_std, 1e-5, 1);
  c.turn_view_above_deg =
      f.NumberOr(m, "turn_view_above_deg", "assistant.monitor", c.turn_view_above_deg, 0, 180, "deg");
  c.turn_view_leaves_deg =
      f.NumberOr(m, "turn_view_leaves_deg", "assistant.monitor", c.turn_view_leaves_deg, 0, 180, "deg");
  c.view_turn_deg_per_s =
      f.NumberOr(m, "view_turn_deg_per_s", "assistant.monitor", c.view_turn_deg_per_s, 1e-3, 1e4, "deg/s");
  c.view_zoom_s = f.NumberOr(m, "view_zoom_s", "assistant.monitor", c.view_zoom_s, 0, 600, "s");
  if (c.turn_view_leaves_deg > c.turn_view_above_deg) {
    throw std::runtime_error(
        path + ": assistant.monitor.turn_view_leaves_deg (" + std::to_string(c.turn_view_leaves_deg) +
        ") must not exceed turn_view_above_deg (" + std::to_string(c.turn_view_above_deg) + ")");
  }

  const YAML::Node act = f.Section(a, "acting", "assistant.acting");
  f.CheckKeys(act, "assistant.acting",
              {"match_margin", "looks_per_joint", "correction_window_deg", "placement_noise_deg",
               "flange_marker_offset_m", "choice"});
  c.match_margin = f.NumberOr(act, "match_margin", "assistant.acting", c.match_margin, 1e-3, 1e6);
  c.looks_per_joint =
      static_cast<int>(f.IntegerOr(act, "looks_per_joint", "assistant.acting", c.looks_per_joint, 1, 10));
  c.correction_window_deg =
      f.NumberOr(act, "correction_window_deg", "assistant.acting", c.correction_window_deg, 0.5, 360, "deg");
  c.placement_noise_deg =
      f.NumberOr(act, "placement_noise_deg", "assistant.acting", c.placement_noise_deg, 0, 45, "deg");
  c.flange_marker_offset_m =
      f.NumberOr(act, "flange_marker_offset_m", "assistant.acting", c.flange_marker_offset_m, 0, 0.5, "m");
  c.choice = f.OneOfOr(act, "choice", "assistant.acting", "nearest", {"nearest", "best"}) == "best"
                 ? Choice::kBest
                 : Choice::kNearest;

  const YAML::Node t = f.Section(a, "time", "assistant.time");
  f.CheckKeys(
      t, "assistant.time",
      {"joint_overhead_s", "look_s", "mental_rotation_deg_per_s", "hand_speed_deg_per_s", "pace_log_sigma"});
  c.joint_overhead_s = f.NumberOr(t, "joint_overhead_s", "assistant.time", c.joint_overhead_s, 0, 600, "s");
  c.look_s = f.NumberOr(t, "look_s", "assistant.time", c.look_s, 0, 600, "s");
  c.mental_rotation_deg_per_s = f.NumberOr(t, "mental_rotation_deg_per_s", "assistant.time",
                                           c.mental_rotation_deg_per_s, 1e-3, 1e4, "deg/s");
  c.hand_speed_deg_per_s =
      f.NumberOr(t, "hand_speed_deg_per_s", "assistant.time", c.hand_speed_deg_per_s, 1e-3, 1e4, "deg/s");
  c.pace_log_sigma = f.NumberOr(t, "pace_log_sigma", "assistant.time", c.pace_log_sigma, 0, 2);
  return c;
}

Assistant::Assistant(const sim::RobotModel& model, const AssistantConfig& config)
    : model_(&model), config_(config), rng_(config.seed) {
  CheckConfig(config_);
  scale_ = rng_.LogNormalUnitMedian(config_.user_scale_log_sigma);
  // The pace from a stream of its own: the person's other draws stay what they were without it.
  Random pace_stream(SplitMix64(config_.seed ^ kPaceStreamTag));
  const double sigma = config_.pace_log_sigma;
  pace_ = std::exp(sigma * pace_stream.Normal() - 0.5 * sigma * sigma);
  const int n = model.num_joints();
  features_.resize(n);
  last_link_.assign(n, 0);
  for (int j = 0; j < n; ++j) {
    AddBody(model, model.links()[model.joints()[j].link].body, config_.flange_marker_offset_m, &features_[j]);
    if (j + 1 < n) {
      AddBody(model, model.links()[model.joints()[j + 1].link].body, config_.flange_marker_offset_m,
              &features_[j]);
    }
    for (const Feature& f : features_[j]) last_link_[j] = std::max(last_link_[j], f.link);
  }
}

Perceived Assistant::PerceiveTarget(int joint, const Eigen::VectorXd& q_target, const Viewing& view) {
  const std::vector<Eigen::Isometry3d> X_RL = model_->CalcLinkPoses(q_target);
  Perceived seen;
  if (view.mode != orbed::guidance_t::MODE_FIXED_DISPLAY) {
    // The hologram, seen from the eye; in MODE_AR_REFLECTIVE also in the display, from its camera.
    for (const Feature& f : features_[joint]) {
      seen.eye.push_back(Perturb(view.X_WV_seen * (X_RL[f.link] * f.p_L), view.p_WE,
                                 scale_ * config_.lateral_noise_arcmin * kArcminToRad,
                                 scale_ * config_.depth_noise_fraction_std, &rng_));
    }
    if (view.mode == orbed::guidance_t::MODE_AR_REFLECTIVE && view.p_WC_display) {
      for (const Feature& f : features_[joint]) {
        seen.display.push_back(Perturb(view.X_WV_display * (X_RL[f.link] * f.p_L), *view.p_WC_display,
                                       scale_ * config_.display_noise_arcmin * kArcminToRad,
                                       scale_ * config_.display_depth_fraction_std, &rng_));
      }
    }
    return seen;
  }
  // The monitor's picture turned into the person's view: a rotation about the vertical through the
  // base (its spread growing with the angle between the picture's viewpoint and the eye) and a
  // scale about the base, per look; read with the picture's noise along the monitor camera's rays.
  const double sigma_deg = RotationErrorStdDeg(MonitorDisparityDeg(view));
  const double psi = scale_ * sigma_deg * kDegToRad * rng_.Normal();
  const double k = std::exp(scale_ * config_.picture_scale_log_sigma * rng_.Normal());
  const Eigen::Matrix3d R_turn = Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d p_WR = view.X_WR.translation();
  for (const Feature& f : features_[joint]) {
    const Eigen::Vector3d p = view.X_WR * (X_RL[f.link] * f.p_L);
    seen.eye.push_back(Perturb(p_WR + k * (R_turn * (p - p_WR)), view.p_WD.value_or(config_.monitor_camera_m),
                               scale_ * config_.picture_noise_arcmin * kArcminToRad,
                               scale_ * config_.picture_depth_fraction_std, &rng_));
  }
  return seen;
}

double Assistant::Discrepancy(int joint, double x_rad, const Eigen::VectorXd& q_now, const Perceived& seen,
                              const Viewing& view) const {
  Eigen::VectorXd q = q_now;
  q[joint] = x_rad;
  return DiscrepancyAt(joint, model_->CalcLinkPoses(q), seen, view);
}

double Assistant::DiscrepancyAt(int joint, const std::vector<Eigen::Isometry3d>& X_RL, const Perceived& seen,
                                const Viewing& view) const {
  const std::vector<Feature>& features = features_[joint];
  const bool display = !seen.display.empty() && view.p_WC_display;
  double sum = 0;
  for (size_t i = 0; i < features.size(); ++i) {
    // The real point against the target's point where it appears: a registration's shift and tilt
    // both reach the joint (file comment).
    const Eigen::Vector3d r = view.X_WR * (X_RL[features[i].link] * features[i].p_L);
    sum += WeightedSquare(r - seen.eye[i], r, view.p_WE, config_.lateral_noise_arcmin * kArcminToRad,
                          config_.depth_noise_fraction_std);
    if (display) {
      sum += WeightedSquare(r - seen.display[i], r, *view.p_WC_display,
                            config_.display_noise_arcmin * kArcminToRad, config_.display_depth_fraction_std);
    }
  }
  return sum;
}

JointLook Assistant::Look(int joint, const Eigen::VectorXd& q_now, const Eigen::VectorXd& q_target,
                          const Viewing& view, double window_rad) {
  if (joint < 0 || joint >= model_->num_joints() || q_now.size() != model_->num_joints() ||
      q_target.size() != model_->num_joints()) {
    throw std::invalid_argument("Assistant::Look: joint or vector size does not match the model");
  }
  const sim::JointInfo& info = model_->joints()[joint];
  const Perceived seen = PerceiveTarget(joint, q_target, view);
  const double lo = std::max(info.lower_rad, q_now[joint] - window_rad);
  const double hi = std::min(info.upper_rad, q_now[joint] + window_rad);
  const double step = kGridStepDeg * kDegToRad;
  const int count = std::max(1, static_cast<int>(std::floor((hi - lo) / step)) + 1);
  std::vector<double> x(count), d(count);
  double d_min = std::numeric_limits<double>::infinity();
  int i_min = 0;
  // Discrepancy(joint, x, ...) without its allocations: the links before the joint keep q_now's
  // poses; only those it moves, up to the last one it is judged by, are recomputed (the same bits).
  Eigen::VectorXd q = q_now;
  std::vector<Eigen::Isometry3d> X_RL = model_->CalcLinkPoses(q_now);
  for (int i = 0; i < count; ++i) {
    x[i] = std::min(hi, lo + i * step);
    q[joint] = x[i];
    model_->UpdateLinkPosesForJoint(q, joint, last_link_[joint], &X_RL);
    d[i] = DiscrepancyAt(joint, X_RL, seen, view);
    if (d[i] < d_min) {
      d_min = d[i];
      i_min = i;
    }
  }
  // The angles that look right, and the one of them the person turns to.
  JointLook look;
  double best_distance = std::numeric_limits<double>::infinity();
  bool inside = false;
  for (int i = 0; i < count; ++i) {
    const bool right = d[i] <= d_min + config_.match_margin;
    if (right && !inside) ++look.ranges;
    inside = right;
    if (right && std::abs(x[i] - q_now[joint]) < best_distance) {
      best_distance = std::abs(x[i] - q_now[joint]);
      look.aim_rad = x[i];
    }
  }
  if (config_.choice == Choice::kBest) look.aim_rad = x[i_min];
  const double placed = look.aim_rad + scale_ * config_.placement_noise_deg * kDegToRad * rng_.Normal();
  look.q_rad = std::clamp(placed, info.lower_rad, info.upper_rad);
  look.time_s = pace_ * config_.look_s;
  if (view.mode == orbed::guidance_t::MODE_FIXED_DISPLAY)
    look.time_s += pace_ * MonitorDisparityDeg(view) / config_.mental_rotation_deg_per_s;
  if (view.mode == orbed::guidance_t::MODE_AR_REFLECTIVE && view.p_WC_display)
    look.time_s += pace_ * config_.display_consult_s;
  return look;
}

double Assistant::TravelTime_s(double delta_rad) const {
  return pace_ * std::abs(delta_rad) * kRadToDeg / config_.hand_speed_deg_per_s;
}

double Assistant::MonitorDisparityDeg(const Viewing& view) const {
  const Eigen::Vector3d p_WR = view.X_WR.translation();
  Eigen::Vector2d a = (view.p_WD.value_or(config_.monitor_camera_m) - p_WR).head<2>();
  Eigen::Vector2d b = (view.p_WE - p_WR).head<2>();
  if (a.norm() < 1e-9 || b.norm() < 1e-9) return 0;
  const double cos_angle = std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0);
  return std::acos(cos_angle) * kRadToDeg;
}

double Assistant::RotationErrorStdDeg(double disparity_deg) const {
  return config_.rotation_error_base_deg + config_.rotation_error_per_deg * disparity_deg;
}

MonitorTurn Assistant::PlanMonitorView(const Viewing& view) const {
  const Eigen::Vector3d p_WR = view.X_WR.translation();
  MonitorTurn turn;
  turn.p_WD = view.p_WD.value_or(config_.monitor_camera_m);
  const double theta = MonitorDisparityDeg(view);
  if (theta > config_.turn_view_above_deg) {
    // Orbit about the vertical through the base, towards the eye's side, until turn_view_leaves_deg
    // is left.
    const Eigen::Vector2d a = (turn.p_WD - p_WR).head<2>(), b = (view.p_WE - p_WR).head<2>();
    const double sign = a.x() * b.y() - a.y() * b.x() >= 0 ? 1.0 : -1.0;
    turn.turned_deg = theta - config_.turn_view_leaves_deg;
    const Eigen::AngleAxisd R(sign * turn.turned_deg * kDegToRad, Eigen::Vector3d::UnitZ());
    turn.p_WD = p_WR + R * (turn.p_WD - p_WR);
  }
  const double eye_m = (view.p_WE - p_WR).norm(), camera_m = (turn.p_WD - p_WR).norm();
  if (camera_m > eye_m && eye_m > 1e-9) {
    turn.zoomed = true;
    turn.p_WD = p_WR + (eye_m / camera_m) * (turn.p_WD - p_WR);
  }
  turn.time_s =
      pace_ * (turn.turned_deg / config_.view_turn_deg_per_s + (turn.zoomed ? config_.view_zoom_s : 0.0));
  return turn;
}

}  // namespace orbed::assistant
