#include "hmd_emulator/slam_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/hash.h"
#include "base/units.h"
#include "base/yaml_fields.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

// The rigid motion that rotates by yaw_rad about the vertical axis through p_W, then translates by t_W.
Eigen::Isometry3d YawAboutPoint(const Eigen::Vector3d& p_W, double yaw_rad, const Eigen::Vector3d& t_W) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() = p_W - X.linear() * p_W + t_W;
  return X;
}

double YawOf(const Eigen::Isometry3d& X) { return std::atan2(X.linear()(1, 0), X.linear()(0, 0)); }

Eigen::Matrix3d ExpRotation(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// The `faults:` list (slam_model.h's file comment), checked.
std::vector<ScheduledFault> ParseFaults(const YamlFields& f, const YAML::Node& list, const std::string& key,
                                        double rate_hz) {
  if (!list.IsSequence() || list.size() > 1000) f.Fail(list, key, "expected a list of at most 1000 faults");
  std::vector<ScheduledFault> faults;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node e = list[i];
    const std::string k = key + "[" + std::to_string(i) + "]";
    f.CheckKeys(e, k, {"session", "trial", "at_s", "state", "duration_s", "jump"});
    ScheduledFault s;
    s.session_id = f.StringOr(e, "session", k, "");
    s.trial_index =
        static_cast<int>(f.Integer(f.Required(e, "trial", k + ".trial"), k + ".trial", 0, 1000000));
    s.timed.at_s = f.Number(f.Required(e, "at_s", k + ".at_s"), k + ".at_s", 0, 3600, "s");
    const std::string state =
        f.OneOf(f.Required(e, "state", k + ".state"), k + ".state", {"limited", "lost"});
    s.timed.fault.state = state == "lost" ? TrackingState::kLost : TrackingState::kLimited;
    s.timed.fault.duration_s =
        f.Number(f.Required(e, "duration_s", k + ".duration_s"), k + ".duration_s", 1.0 / rate_hz, 60, "s");
    if (e["jump"]) {
      const std::string kj = k + ".jump";
      f.CheckKeys(e["jump"], kj, {"position_m", "yaw_deg"});
      if (e["jump"]["position_m"]) {
        s.timed.fault.jump_W_m = f.Vector3(e["jump"]["position_m"], kj + ".position_m", "m");
        if (!(s.timed.fault.jump_W_m.norm() <= 1.0))
          f.Fail(e["jump"]["position_m"], kj + ".position_m", "at most 1 m");
      }
      s.timed.fault.jump_yaw_deg = f.NumberOr(e["jump"], "yaw_deg", kj, 0.0, -45, 45, "deg");
    }
    for (const ScheduledFault& earlier : faults) {
      const bool same_trial =
          earlier.trial_index == s.trial_index &&
          (earlier.session_id.empty() || s.session_id.empty() || earlier.session_id == s.session_id);
      if (same_trial && !(s.timed.at_s > earlier.timed.at_s + earlier.timed.fault.duration_s)) {
        f.Fail(e["at_s"], k + ".at_s",
               "after the end of the trial's earlier fault (at_s " + std::to_string(earlier.timed.at_s) +
                   " + duration_s " + std::to_string(earlier.timed.fault.duration_s) + ")");
      }
    }
    faults.push_back(s);
  }
  return faults;
}

}  // namespace

const char* TrackingStateName(TrackingState state) {
  switch (state) {
    case TrackingState::kTracking:
      return "tracking";
    case TrackingState::kLimited:
      return "limited";
    case TrackingState::kLost:
      return "lost";
    case TrackingState::kRelocalized:
      return "relocalized";
  }
  return "unknown";
}

SlamConfig ParseSlamConfig(const YAML::Node& node, const std::string& source, const std::string& key,
                           const SlamConfig& base) {
  const YamlFields f(source);
  f.CheckKeys(node, key,
              {"seed", "rate_hz", "head_to_camera", "jitter", "drift", "anchors", "tracking_loss", "faults"});
  SlamConfig c = base;
  c.seed = static_cast<std::uint64_t>(
      f.IntegerOr(node, "seed", key, static_cast<long long>(c.seed), 0, (1LL << 62)));
  c.rate_hz = f.NumberOr(node, "rate_hz", key, c.rate_hz, 1.0, 1000.0, "Hz");
  if (node["head_to_camera"]) {
    const std::string k = key + ".head_to_camera";
    const YAML::Node h = node["head_to_camera"];
    f.CheckKeys(h, k, {"position_m", "rpy_deg"});
    if (h["position_m"]) c.X_HC.translation() = f.Vector3(h["position_m"], k + ".position_m", "m");
    if (h["rpy_deg"])
      c.X_HC.linear() = sim::RotationFromRpyDeg(f.Vector3(h["rpy_deg"], k + ".rpy_deg", "deg"));
  }
  const YAML::Node j = f.Section(node, "jitter", key + ".jitter");
  const std::string kj = key + ".jitter";
  f.CheckKeys(j, kj, {"translation_std_m", "rotation_std_deg"});
  c.jitter_translation_std_m =
      f.NumberOr(j, "translation_std_m", kj, c.jitter_translation_std_m, 0, 0.1, "m");
  c.jitter_rotation_std_deg = f.NumberOr(j, "rotation_std_deg", kj, c.jitter_rotation_std_deg, 0, 5, "deg");
  const YAML::Node d = f.Section(node, "drift", key + ".drift");
  const std::string kd = key + ".drift";
  f.CheckKeys(d, kd,
              {"fraction_of_distance", "session_log_sigma", "yaw_deg_per_m", "direction_correlation_m",
               "band_fraction"});
  c.drift_fraction_of_distance =
      f.NumberOr(d, "fraction_of_distance", kd, c.drift_fraction_of_distance, 0, kMaxDriftFraction);
  c.drift_session_log_sigma = f.NumberOr(d, "session_log_sigma", kd, c.drift_session_log_sigma, 0, 2);
  c.drift_yaw_deg_per_m = f.NumberOr(d, "yaw_deg_per_m", kd, c.drift_yaw_deg_per_m, 0, 10, "deg/m");
  c.drift_direction_correlation_m =
      f.NumberOr(d, "direction_correlation_m", kd, c.drift_direction_correlation_m, 0.01, 1e6, "m");
  if (d["band_fraction"]) {
    const YAML::Node b = d["band_fraction"];
    if (!b.IsSequence() || b.size() != 2)
      f.Fail(b, kd + ".band_fraction", "expected [min, max] with 0 <= min <= max");
    c.drift_band_min_fraction = f.Number(b[0], kd + ".band_fraction[0]", 0, 0.2);
    c.drift_band_max_fraction = f.Number(b[1], kd + ".band_fraction[1]", c.drift_band_min_fraction, 0.2);
  }
  const YAML::Node a = f.Section(node, "anchors", key + ".anchors");
  const std::string ka = key + ".anchors";
  f.CheckKeys(a, ka, {"radius_m", "relock_correction"});
  c.anchor_radius_m = f.NumberOr(a, "radius_m", ka, c.anchor_radius_m, 0, 10, "m");
  c.anchor_relock_correction = f.NumberOr(a, "relock_correction", ka, c.anchor_relock_correction, 0, 1);
  const YAML::Node t = f.Section(node, "tracking_loss", key + ".tracking_loss");
  const std::string kt = key + ".tracking_loss";
  f.CheckKeys(t, kt,
              {"rate_per_min", "limited_mean_s", "limited_drift_multiplier", "lost_probability",
               "lost_mean_s", "relocalization_correction", "jump_translation_std_m", "jump_yaw_std_deg"});
  c.tracking_loss_rate_per_min =
      f.NumberOr(t, "rate_per_min", kt, c.tracking_loss_rate_per_min, 0, 600, "1/min");
  c.limited_mean_s = f.NumberOr(t, "limited_mean_s", kt, c.limited_mean_s, 1e-3, 600, "s");
  c.limited_drift_multiplier =
      f.NumberOr(t, "limited_drift_multiplier", kt, c.limited_drift_multiplier, 0, 100);
  c.lost_probability = f.NumberOr(t, "lost_probability", kt, c.lost_probability, 0, 1);
  c.lost_mean_s = f.NumberOr(t, "lost_mean_s", kt, c.lost_mean_s, 1e-3, 600, "s");
  c.relocalization_correction =
      f.NumberOr(t, "relocalization_correction", kt, c.relocalization_correction, 0, 1);
  c.jump_translation_std_m = f.NumberOr(t, "jump_translation_std_m", kt, c.jump_translation_std_m, 0, 1, "m");
  c.jump_yaw_std_deg = f.NumberOr(t, "jump_yaw_std_deg", kt, c.jump_yaw_std_deg, 0, 45, "deg");
  if (node["faults"]) c.faults = ParseFaults(f, node["faults"], key + ".faults", c.rate_hz);
  return c;
}

SlamConfig LoadSlamConfigFile(const std::string& path) {
  const YAML::Node root = YamlFields::LoadFile(path);
  const YamlFields f(path);
  f.CheckKeys(root, "", {"slam"});
  return ParseSlamConfig(f.Required(root, "slam", "slam"), path);
}

SlamConfig SessionSlamConfig(const SlamConfig& base, std::uint64_t session_seed) {
  constexpr std::uint64_t kDriftSalt = 0x6472696674726174ULL;  // "driftrat"
  SlamConfig c = base;
  c.seed = session_seed;
  Random rng(SplitMix64(session_seed ^ kDriftSalt));
  // Within what the parser accepts for a fixed rate (a log-normal's tail reaches beyond it).
  c.drift_fraction_of_distance =
      std::min(kMaxDriftFraction,
               base.drift_fraction_of_distance * std::exp(base.drift_session_log_sigma * rng.Normal()));
  return c;
}

SlamModel::SlamModel(const SlamConfig& config) : config_(config), rng_(config.seed) {}

void SlamModel::UpdateAnchors(const Eigen::Vector3d& p_WH, double ds_m) {
  const double r = config_.anchor_radius_m;
  bool near_one = false;
  for (Anchor& a : anchors_) {
    const bool inside = (p_WH - a.p_W).norm() <= r;
    near_one = near_one || inside;
    if (inside && !a.inside) {
      // Back at a stored place: re-matched to what was stored there, about the head.
      const double keep = 1.0 - config_.anchor_relock_correction;
      const Eigen::Vector3d e_now = E_ * p_WH - p_WH;
      const Eigen::Vector3d e_stored = a.E * p_WH - p_WH;
      const double yaw_stored = YawOf(a.E);
      const double d_yaw = std::remainder(YawOf(E_) - yaw_stored, 2 * M_PI);  // the short way round
      E_ = YawAboutPoint(p_WH, yaw_stored + keep * d_yaw, e_stored + keep * (e_now - e_stored));
      ++relocks_;
    }
    a.inside = inside;
  }
  // Standing still away from every stored place: the device stores this one with today's error.
  if (!near_one && ds_m == 0) anchors_.push_back({p_WH, E_, true});
}

void SlamModel::Force(const ForcedFault& fault) {
  if (fault.state != TrackingState::kLimited && fault.state != TrackingState::kLost) {
    throw std::invalid_argument("SlamModel::Force: the state must be limited or lost");
  }
  if (!(fault.duration_s > 0)) throw std::invalid_argument("SlamModel::Force: duration_s must be positive");
  pending_force_ = fault;
}

void SlamModel::Drift(const Eigen::Vector3d& p_WH, double ds_m, double multiplier) {
  if (!(ds_m > 0) || multiplier == 0) return;
  const double L = config_.drift_direction_correlation_m;
  // Brownian motion on the unit sphere: two tangent components of variance ds/L each give
  // E[u(s)·u(0)] = exp(−s/L); the scalar phase with variance 2 ds/L gives E[cos Δφ] = exp(−s/L).
  drift_dir_ = (drift_dir_ + std::sqrt(ds_m / L) * rng_.Normal3()).normalized();
  yaw_phase_rad_ += std::sqrt(2.0 * ds_m / L) * rng_.Normal();
  const Eigen::Vector3d dt_W = multiplier * config_.drift_fraction_of_distance * ds_m * drift_dir_;
  const double dyaw = multiplier * config_.drift_yaw_deg_per_m * kDegToRad * ds_m * std::cos(yaw_phase_rad_);
  E_ = YawAboutPoint(p_WH, dyaw, dt_W) * E_;
}

void SlamModel::AdvanceState(double dt_s) {
  switch (state_) {
    case TrackingState::kRelocalized:
      state_ = TrackingState::kTracking;
      [[fallthrough]];
    case TrackingState::kTracking: {
      const double rate_per_s = random_losses_ ? config_.tracking_loss_rate_per_min / 60.0 : 0.0;
      if (rate_per_s > 0 && rng_.Uniform() < 1.0 - std::exp(-rate_per_s * dt_s)) {
        state_ = TrackingState::kLimited;
        state_left_s_ = rng_.Exponential(config_.limited_mean_s);
        lost_follows_ = rng_.Uniform() < config_.lost_probability;
      }
      break;
    }
    case TrackingState::kLimited:
      state_left_s_ -= dt_s;
      if (state_left_s_ <= 0) {
        if (lost_follows_) {
          state_ = TrackingState::kLost;
          state_left_s_ = rng_.Exponential(config_.lost_mean_s);
        } else {
          state_ = TrackingState::kRelocalized;
        }
      }
      break;
    case TrackingState::kLost:
      state_left_s_ -= dt_s;
      if (state_left_s_ <= 0) state_ = TrackingState::kRelocalized;
      break;
  }
}

SlamSample SlamModel::Step(const Eigen::Isometry3d& X_WH_true, double t_s) {
  const Eigen::Vector3d p_WH = X_WH_true.translation();
  if (!started_) {
    started_ = true;
    last_t_s_ = t_s;
    last_p_WH_ = p_WH;
    drift_dir_ = rng_.Normal3().normalized();
    yaw_phase_rad_ = rng_.Uniform(0, 2 * M_PI);
  }
  if (!(t_s >= last_t_s_)) throw std::invalid_argument("SlamModel::Step: time went backwards");
  const double dt = t_s - last_t_s_;
  const double ds = (p_WH - last_p_WH_).norm();
  path_m_ += ds;

  const TrackingState before = state_;
  if (pending_force_) {
    forced_ = pending_force_;
    pending_force_.reset();
    state_ = forced_->state;
    forced_samples_left_ = std::max(1LL, std::llround(forced_->duration_s * config_.rate_hz)) - 1;
  } else if (forced_) {
    if (forced_samples_left_ > 0) {
      --forced_samples_left_;
    } else {
      state_ = TrackingState::kRelocalized;
    }
  } else if (seq_ > 0) {
    AdvanceState(dt);
  }
  if (state_ == TrackingState::kRelocalized && before != TrackingState::kRelocalized) {
    // Re-matched to the stored map: shrink the accumulated error about the head, then jump.
    const double keep = 1.0 - config_.relocalization_correction;
    const Eigen::Vector3d e_head = E_ * p_WH - p_WH;  // the head's position error before
    const Eigen::Isometry3d shrunk = YawAboutPoint(p_WH, keep * YawOf(E_), keep * e_head);
    Eigen::Isometry3d jump;
    if (forced_) {
      jump = YawAboutPoint(p_WH, forced_->jump_yaw_deg * kDegToRad, forced_->jump_W_m);
      forced_.reset();
    } else {
      // The translation drawn before the yaw, one per statement (as the pinned runs: the order of
      // a call's arguments is unspecified, and GCC evaluates them last first).
      const Eigen::Vector3d jump_t_W = config_.jump_translation_std_m * rng_.Normal3();
      const double jump_yaw = config_.jump_yaw_std_deg * kDegToRad * rng_.Normal();
      jump = YawAboutPoint(p_WH, jump_yaw, jump_t_W);
    }
    E_ = jump * shrunk;
  } else if (state_ != TrackingState::kLost) {
    Drift(p_WH, ds, state_ == TrackingState::kLimited ? config_.limited_drift_multiplier : 1.0);
  }
  if (config_.anchor_radius_m > 0 && config_.anchor_relock_correction > 0 &&
      state_ == TrackingState::kTracking) {
    UpdateAnchors(p_WH, ds);
  }

  SlamSample s;
  s.t_s = t_s;
  s.seq = seq_++;
  s.path_m = path_m_;
  s.X_WH_true = X_WH_true;
  s.X_WC_true = X_WH_true * config_.X_HC;
  s.X_WWmap = E_;
  s.state = state_;
  if (state_ == TrackingState::kLost) {
    s.X_WH_est = frozen_X_WH_est_;  // the device holds its last pose while lost
  } else {
    Eigen::Isometry3d J_H = Eigen::Isometry3d::Identity();
    J_H.linear() = ExpRotation(config_.jitter_rotation_std_deg * kDegToRad * rng_.Normal3());
    J_H.translation() = config_.jitter_translation_std_m * rng_.Normal3();
    s.X_WH_est = E_.inverse() * X_WH_true * J_H;
    frozen_X_WH_est_ = s.X_WH_est;
  }
  s.X_WC_est = s.X_WH_est * config_.X_HC;
  last_t_s_ = t_s;
  last_p_WH_ = p_WH;
  return s;
}

std::vector<SlamSample> SimulateWalk(const HeadTrajectory& trajectory, const SlamConfig& config,
                                     double t_end_s) {
  SlamModel model(config);
  std::vector<SlamSample> samples;
  const double dt = 1.0 / config.rate_hz;
  const long long n = static_cast<long long>(std::floor(t_end_s / dt + 1e-9)) + 1;
  samples.reserve(static_cast<std::size_t>(std::max(0LL, n)));
  for (long long k = 0; k < n; ++k) {
    const double t = k * dt;
    samples.push_back(model.Step(trajectory.X_WH(t), t));
  }
  return samples;
}

}  // namespace orbed::hmd
