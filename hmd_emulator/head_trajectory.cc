#include "hmd_emulator/head_trajectory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "base/yaml_fields.h"

namespace orbed::hmd {
namespace {

// The parameter a in [0, 1] where v0 + a (v1 − v0) is shortest.
template <int N>
double ClosestToZero(const Eigen::Matrix<double, N, 1>& v0, const Eigen::Matrix<double, N, 1>& v1) {
  const Eigen::Matrix<double, N, 1> dv = v1 - v0;
  const double dd = dv.squaredNorm();
  return dd > 0 ? std::clamp(-v0.dot(dv) / dd, 0.0, 1.0) : 0.0;
}

}  // namespace

HeadTrajectoryConfig ParseHeadTrajectory(const YAML::Node& node, const std::string& source,
                                         const std::string& key) {
  const YamlFields f(source);
  f.CheckKeys(node, key, {"speed_m_per_s", "look_at_m", "loop", "waypoints"});
  HeadTrajectoryConfig c;
  c.speed_m_per_s = f.Number(f.Required(node, "speed_m_per_s", key + ".speed_m_per_s"),
                             key + ".speed_m_per_s", 1e-3, 10.0, "m/s");
  c.p_W_look_at = f.Vector3(f.Required(node, "look_at_m", key + ".look_at_m"), key + ".look_at_m", "m");
  c.loop = f.BoolOr(node, "loop", key, false);
  const YAML::Node wps = f.Required(node, "waypoints", key + ".waypoints");
  if (!wps.IsSequence() || wps.size() == 0)
    f.Fail(wps, key + ".waypoints", "expected a list of >= 1 waypoints");
  for (std::size_t i = 0; i < wps.size(); ++i) {
    const std::string k = key + ".waypoints[" + std::to_string(i) + "]";
    const YAML::Node w = wps[i];
    f.CheckKeys(w, k, {"name", "position_m", "dwell_s", "look_at_m"});
    HeadWaypoint wp;
    wp.name = f.StringOr(w, "name", k, "waypoint" + std::to_string(i));
    wp.p_WH = f.Vector3(f.Required(w, "position_m", k + ".position_m"), k + ".position_m", "m");
    wp.dwell_s = f.NumberOr(w, "dwell_s", k, 0.0, 0.0, 3600.0, "s");
    if (w["look_at_m"]) wp.p_W_look_at = f.Vector3(w["look_at_m"], k + ".look_at_m", "m");
    c.waypoints.push_back(wp);
  }
  try {
    HeadTrajectory check(c);
  } catch (const std::invalid_argument& e) {
    f.Fail(node, key, e.what());
  }
  return c;
}

HeadTrajectoryConfig LoadHeadTrajectoryFile(const std::string& path) {
  const YAML::Node root = YamlFields::LoadFile(path);
  const YamlFields f(path);
  return ParseHeadTrajectory(f.Required(root, "head_trajectory", "head_trajectory"), path);
}

HeadTrajectory::HeadTrajectory(HeadTrajectoryConfig config) : config_(std::move(config)) {
  const auto& w = config_.waypoints;
  if (w.empty()) throw std::invalid_argument("head trajectory: needs at least one waypoint");
  if (!(config_.speed_m_per_s > 0) || !std::isfinite(config_.speed_m_per_s)) {
    throw std::invalid_argument("head trajectory: speed_m_per_s must be > 0");
  }
  const int n = static_cast<int>(w.size());
  for (int i = 0; i < n; ++i) {
    if (!(w[i].dwell_s >= 0)) {
      throw std::invalid_argument("head trajectory: waypoint '" + w[i].name + "': dwell_s must be >= 0");
    }
    try {
      geometry::LookAt(w[i].p_WH, Target(i));  // throws when the target is degenerate
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("head trajectory: at waypoint '" + w[i].name + "': " + e.what());
    }
  }
  const int num_segments = config_.loop ? n : n - 1;
  // While walking a segment the line of sight d(a) = target(a) − p(a) is linear in the fraction a
  // walked, and so is its horizontal part: X_WH() must never meet a vertical (or vanishing) line of
  // sight there, or it would throw mid-walk. |d(a)| >= |d(a*)| and the heading is defined wherever
  // |horizontal(a)| / |d(a)| > 1e-6 (geometry::LookAt), which the bound |d(a)| <= max(|d_i|, |d_j|) (d is
  // convex in a) guarantees when the horizontal part's minimum exceeds 1e-6 · max(|d_i|, |d_j|).
  for (int i = 0; i < num_segments; ++i) {
    const int j = (i + 1) % n;
    const Eigen::Vector3d d_i = Target(i) - w[i].p_WH, d_j = Target(j) - w[j].p_WH;
    const double a_near = ClosestToZero<3>(d_i, d_j);
    const Eigen::Vector2d h_i = d_i.head<2>(), h_j = d_j.head<2>();
    const double a_vertical = ClosestToZero<2>(h_i, h_j);
    const bool near = !(((1 - a_near) * d_i + a_near * d_j).norm() > 1e-3);
    const double h_min = ((1 - a_vertical) * h_i + a_vertical * h_j).norm();
    const bool vertical = !(h_min > 1e-6 * std::max(d_i.norm(), d_j.norm()));
    if (near || vertical) {
      const double a = near ? a_near : a_vertical;
      const Eigen::Vector3d p = (1 - a) * w[i].p_WH + a * w[j].p_WH;
      char where[120];
      std::snprintf(where, sizeof(where), "%.0f %% of the way, at (%.3f, %.3f, %.3f) m", 100 * a, p.x(),
                    p.y(), p.z());
      throw std::invalid_argument(
          "head trajectory: walking from waypoint '" + w[i].name + "' to '" + w[j].name +
          "' the head passes " + (near ? "within 1 mm of" : "straight over or under") +
          " its look-at target (" + where +
          "), where the heading is undefined; move a waypoint or the target off that line");
    }
  }
  double t = 0, s = 0;
  for (int i = 0; i < n; ++i) {
    arrive_s_.push_back(t);
    cum_len_m_.push_back(s);
    t += w[i].dwell_s;
    if (i < num_segments) {
      const double len = (w[(i + 1) % n].p_WH - w[i].p_WH).norm();
      seg_len_m_.push_back(len);
      t += len / config_.speed_m_per_s;
      s += len;
    }
  }
  duration_s_ = t;
  length_m_ = s;
}

Eigen::Vector3d HeadTrajectory::Target(int i) const {
  const auto& wp = config_.waypoints[i];
  return wp.p_W_look_at ? *wp.p_W_look_at : config_.p_W_look_at;
}

int HeadTrajectory::FindWaypoint(const std::string& name) const {
  for (std::size_t i = 0; i < config_.waypoints.size(); ++i) {
    if (config_.waypoints[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

Eigen::Isometry3d HeadTrajectory::X_WH(double t_s) const {
  const auto& w = config_.waypoints;
  const int n = static_cast<int>(w.size());
  double t = std::max(0.0, t_s);
  if (config_.loop && duration_s_ > 0) t = std::fmod(t, duration_s_);
  for (int i = 0; i < n; ++i) {
    const double leave = arrive_s_[i] + w[i].dwell_s;
    if (t <= leave) return geometry::LookAt(w[i].p_WH, Target(i));
    if (i < static_cast<int>(seg_len_m_.size())) {
      const double walk = seg_len_m_[i] / config_.speed_m_per_s;
      if (t <= leave + walk) {
        const double a = walk > 0 ? (t - leave) / walk : 1.0;
        const int j = (i + 1) % n;
        const Eigen::Vector3d p = (1 - a) * w[i].p_WH + a * w[j].p_WH;
        const Eigen::Vector3d target = (1 - a) * Target(i) + a * Target(j);
        return geometry::LookAt(p, target);
      }
    }
  }
  // Past the end of a non-looping path (or rounding at the loop's end): the last / first waypoint.
  const int last = config_.loop ? 0 : n - 1;
  return geometry::LookAt(w[last].p_WH, Target(last));
}

double HeadTrajectory::PathLength(double t_s) const {
  const auto& w = config_.waypoints;
  const int n = static_cast<int>(w.size());
  double t = std::max(0.0, t_s);
  double laps = 0;
  if (config_.loop && duration_s_ > 0) {
    laps = std::floor(t / duration_s_);
    t -= laps * duration_s_;
  }
  double s = laps * length_m_;
  for (int i = 0; i < n; ++i) {
    const double leave = arrive_s_[i] + w[i].dwell_s;
    if (t <= leave) return s + cum_len_m_[i];
    if (i < static_cast<int>(seg_len_m_.size())) {
      const double walk = seg_len_m_[i] / config_.speed_m_per_s;
      if (t <= leave + walk) return s + cum_len_m_[i] + (t - leave) * config_.speed_m_per_s;
    }
  }
  return s + length_m_;
}

}  // namespace orbed::hmd
