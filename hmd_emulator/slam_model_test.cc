// Head trajectory and SLAM error model. Oracles: geometry worked out by hand, the KITTI-style
// relative pose error (Geiger et al. 2012) over 1 m segments against the configured drift, and
// the physical consequences of the hologram relation (head-locked content is unaffected by any
// tracking error; a translational map error shifts every hologram by p_true − p_est; the device's
// camera overlay lands where the true camera sees the apparent hologram).
#include "hmd_emulator/slam_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "base/stats.h"
#include "base/units.h"
#include "base/yaml_fields.h"
#include "geometry/camera_model.h"
#include "orbed/hmd_pose_t.hpp"

namespace orbed::hmd {
namespace {

static_assert(static_cast<int>(TrackingState::kTracking) == orbed::hmd_pose_t::TRACKING);
static_assert(static_cast<int>(TrackingState::kLimited) == orbed::hmd_pose_t::LIMITED);
static_assert(static_cast<int>(TrackingState::kLost) == orbed::hmd_pose_t::LOST);
static_assert(static_cast<int>(TrackingState::kRelocalized) == orbed::hmd_pose_t::RELOCALIZED);

TEST(HeadTrajectory, LookAtAxes) {
  // Looking along +x_W from (1, 2, 1.7): right is −y_W, down is −z_W.
  const Eigen::Isometry3d X_WH = geometry::LookAt({1, 2, 1.7}, {5, 2, 1.7});
  EXPECT_TRUE(X_WH.linear().col(2).isApprox(Eigen::Vector3d(1, 0, 0), 1e-12));
  EXPECT_TRUE(X_WH.linear().col(0).isApprox(Eigen::Vector3d(0, -1, 0), 1e-12));
  EXPECT_TRUE(X_WH.linear().col(1).isApprox(Eigen::Vector3d(0, 0, -1), 1e-12));
  EXPECT_TRUE(X_WH.translation().isApprox(Eigen::Vector3d(1, 2, 1.7)));
  EXPECT_THROW(geometry::LookAt({0, 0, 1}, {0, 0, 3}), std::invalid_argument);
}

TEST(HeadTrajectory, TimingAndPath) {
  HeadTrajectoryConfig c;
  c.speed_m_per_s = 0.5;
  c.p_W_look_at = Eigen::Vector3d(0, 5, 1.0);
  c.waypoints = {{"a", {0, 0, 1.7}, 1.0, {}}, {"b", {2, 0, 1.7}, 3.0, {}}};
  const HeadTrajectory t(c);
  // Dwell 1 s, walk 2 m at 0.5 m/s = 4 s, dwell 3 s.
  EXPECT_DOUBLE_EQ(t.duration_s(), 8.0);
  EXPECT_DOUBLE_EQ(t.length_m(), 2.0);
  EXPECT_DOUBLE_EQ(t.ArrivalTime(1), 5.0);
  EXPECT_DOUBLE_EQ(t.DepartureTime(1), 8.0);
  EXPECT_TRUE(t.X_WH(3.0).translation().isApprox(Eigen::Vector3d(1, 0, 1.7)));  // halfway
  EXPECT_DOUBLE_EQ(t.PathLength(3.0), 1.0);
  EXPECT_TRUE(t.X_WH(100).translation().isApprox(Eigen::Vector3d(2, 0, 1.7)));
  // Always facing the target.
  const Eigen::Isometry3d X = t.X_WH(4.0);
  EXPECT_NEAR(X.linear().col(2).dot((c.p_W_look_at - X.translation()).normalized()), 1.0, 1e-12);
  EXPECT_EQ(t.FindWaypoint("b"), 1);
  EXPECT_EQ(t.FindWaypoint("zz"), -1);
  // Looping: the closing segment back to "a" (2 m) is walked too.
  c.loop = true;
  const HeadTrajectory loop(c);
  EXPECT_DOUBLE_EQ(loop.duration_s(), 12.0);
  EXPECT_DOUBLE_EQ(loop.PathLength(24.0 + 5.0), 2 * 4.0 + 2.0);
}

// A segment walked straight over the look-at target: both waypoints are fine (the target is ahead
// of each), but halfway the line of sight is vertical. The constructor refuses the walk, naming the
// segment's waypoints, instead of X_WH() throwing mid-walk (inside orbed-hmd's 60 Hz timer).
TEST(HeadTrajectory, SegmentOverTheTargetIsRefusedUpFront) {
  HeadTrajectoryConfig c;
  c.speed_m_per_s = 1.0;
  c.p_W_look_at = Eigen::Vector3d(0, 0, 1.0);
  c.waypoints = {{"west", {-1, 0, 1.7}, 0, {}}, {"east", {1, 0, 1.7}, 0, {}}};
  try {
    const HeadTrajectory t(c);
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("from waypoint 'west' to 'east'"), std::string::npos) << what;
    EXPECT_NE(what.find("straight over or under"), std::string::npos) << what;
    EXPECT_NE(what.find("50 % of the way, at (0.000, 0.000, 1.700) m"), std::string::npos) << what;
  }
  // Passing 1 m beside the target is fine, and every pose along the segment is defined.
  c.waypoints[1].p_WH = Eigen::Vector3d(1, 1, 1.7);
  c.waypoints[0].p_WH = Eigen::Vector3d(-1, 1, 1.7);
  const HeadTrajectory beside(c);
  for (double t = 0; t <= beside.duration_s(); t += 0.01) EXPECT_NO_THROW(beside.X_WH(t));
  // The loop's closing segment is checked too: east -> west is fine, but a third waypoint whose
  // return leg crosses over the target is not.
  c.loop = true;
  c.waypoints = {{"a", {-1, -1, 1.7}, 0, {}}, {"b", {-1, 1, 1.7}, 0, {}}, {"c", {1, 1, 1.7}, 0, {}}};
  EXPECT_THROW(HeadTrajectory{c}, std::invalid_argument);  // c -> a passes over (0, 0)
  c.loop = false;
  EXPECT_NO_THROW(HeadTrajectory{c});
  // A waypoint right above its target names the waypoint.
  c.waypoints = {{"above", {0, 0, 1.7}, 0, {}}};
  try {
    const HeadTrajectory t(c);
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("waypoint 'above'"), std::string::npos) << e.what();
  }
  // Through the YAML parser the message carries the file and the key.
  try {
    ParseHeadTrajectory(YamlFields::LoadString("speed_m_per_s: 1\nlook_at_m: [0, 0, 1]\nwaypoints:\n"
                                               "  - {name: west, position_m: [-1, 0, 1.7]}\n"
                                               "  - {name: east, position_m: [1, 0, 1.7]}\n",
                                               "w.yaml"),
                        "w.yaml");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("w.yaml:1: head_trajectory: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'west' to 'east'"), std::string::npos) << e.what();
  }
}

// A closed walk around the robot (a 3 m × 2 m rectangle at head height), looped.
HeadTrajectoryConfig RectangleWalk() {
  HeadTrajectoryConfig c;
  c.speed_m_per_s = 0.8;
  c.p_W_look_at = Eigen::Vector3d(0.25, -0.45, 1.25);
  c.loop = true;
  c.waypoints = {{"p0", {-1.25, -1.45, 1.7}, 0, {}},
                 {"p1", {1.75, -1.45, 1.7}, 0, {}},
                 {"p2", {1.75, 0.55, 1.7}, 0, {}},
                 {"p3", {-1.25, 0.55, 1.7}, 0, {}}};
  return c;
}

struct RpeStats {
  std::vector<double> per_metre;
};

// Relative pose error over segments of >= 1 m of true path, only over segments tracked throughout.
RpeStats RelativePoseErrorPerMetre(const std::vector<SlamSample>& s) {
  RpeStats out;
  std::size_t a = 0;
  while (a < s.size()) {
    std::size_t b = a;
    bool tracked = true;
    while (b < s.size() && s[b].path_m - s[a].path_m < 1.0) {
      tracked = tracked && s[b].state == TrackingState::kTracking;
      ++b;
    }
    if (b >= s.size()) break;
    tracked = tracked && s[b].state == TrackingState::kTracking;
    if (tracked) {
      const Eigen::Isometry3d d_true = s[a].X_WH_true.inverse() * s[b].X_WH_true;
      const Eigen::Isometry3d d_est = s[a].X_WH_est.inverse() * s[b].X_WH_est;
      const double err = (d_est.inverse() * d_true).translation().norm();
      out.per_metre.push_back(err / (s[b].path_m - s[a].path_m));
    }
    a = b;
  }
  return out;
}

TEST(SlamModel, DriftPerMetreStaysInConfiguredBand) {
  const SlamConfig shipped = LoadSlamConfigFile(orbed::SourceTreePath(kDefaultSlamConfigRelativePath));
  const HeadTrajectory walk(RectangleWalk());
  for (const double fraction : {shipped.drift_fraction_of_distance, 0.005}) {
    SlamConfig c = shipped;
    c.drift_fraction_of_distance = fraction;
    c.anchor_radius_m = 0;  // the drift law alone: the rectangle's corners would re-match the map
    c.seed = 7;
    // 300 s at 0.8 m/s: 240 m, 24 laps.
    const std::vector<SlamSample> s = SimulateWalk(walk, c, 300.0);
    EXPECT_NEAR(s.back().path_m, 240.0, 0.5);
    const RpeStats rpe = RelativePoseErrorPerMetre(s);
    ASSERT_GT(rpe.per_metre.size(), 150u);
    const double mean = stats::Mean(rpe.per_metre);
    std::printf("configured drift %.4f, measured relative pose error %.4f per metre over %zu segments\n",
                fraction, mean, rpe.per_metre.size());
    EXPECT_GE(mean, c.drift_band_min_fraction) << "fraction " << fraction;
    EXPECT_LE(mean, c.drift_band_max_fraction) << "fraction " << fraction;
    // Closed form for a drift direction decorrelating as exp(−s/L): the RMS drift over ℓ = 1 m is
    // f · √(2 L² (ℓ/L − 1 + e^(−ℓ/L))) = 0.9835 f for L = 10 m; the mean of the norm is a little
    // below the RMS, jitter and yaw add < 0.1 % of distance.
    EXPECT_GT(mean, 0.85 * fraction);
    EXPECT_LT(mean, 1.05 * fraction);
  }
  // The shipped default is inside the documented band.
  EXPECT_GE(shipped.drift_fraction_of_distance, shipped.drift_band_min_fraction);
  EXPECT_LE(shipped.drift_fraction_of_distance, shipped.drift_band_max_fraction);
}

// A model that only drifts (1 % per metre, 0.5 deg of yaw per metre): no jitter, no tracking loss.
SlamConfig DriftOnly(std::uint64_t seed) {
  SlamConfig c;
  c.jitter_translation_std_m = c.jitter_rotation_std_deg = 0;
  c.tracking_loss_rate_per_min = 0;
  c.drift_fraction_of_distance = 0.01;
  c.drift_yaw_deg_per_m = 0.5;
  c.seed = seed;
  return c;
}

Eigen::Isometry3d HeadAt(const Eigen::Vector3d& p_W) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = p_W;
  return X;
}

// Coming back to a stored place moves the head's error relock_correction of the way to the error
// stored there. Oracle: the same model without stored places (same seed: stored places draw
// nothing, so both are identical up to the sample that re-matches).
TEST(SlamModel, ComingBackToAStoredPlaceReMatchesTheMapThere) {
  SlamConfig c = DriftOnly(5);
  for (const double correction : {1.0, 0.5}) {
    SCOPED_TRACE(correction);
    c.anchor_relock_correction = correction;
    SlamConfig free = c;
    free.anchor_radius_m = 0;
    SlamModel anchored(c), unanchored(free);
    // Stand at A (stored with E = I), walk 5 m out along x and straight back.
    const Eigen::Vector3d p_A(0, 0, 1.7);
    double t = 0;
    const double step_m = 0.8 / 60;
    std::vector<Eigen::Vector3d> path = {p_A, p_A};
    for (double x = step_m; x < 5.0; x += step_m) path.push_back(p_A + Eigen::Vector3d(x, 0, 0));
    for (double x = 5.0; x > -1e-9; x -= step_m) path.push_back(p_A + Eigen::Vector3d(x, 0, 0));
    bool relocked = false;
    for (const Eigen::Vector3d& p : path) {
      const SlamSample a = anchored.Step(HeadAt(p), t);
      const SlamSample u = unanchored.Step(HeadAt(p), t);
      t += 1.0 / 60;
      if (relocked || anchored.relocks() == 0) {
        if (!relocked) EXPECT_TRUE(a.X_WWmap.isApprox(u.X_WWmap, 0)) << "before the first re-match";
        continue;
      }
      relocked = true;
      EXPECT_LE((p - p_A).norm(), c.anchor_radius_m + 1e-12);
      EXPECT_GT((p - p_A).norm(), c.anchor_radius_m - step_m);
      const Eigen::Vector3d e_anchored = a.X_WWmap * p - p, e_free = u.X_WWmap * p - p;
      EXPECT_GT(e_free.norm(), 0.01 * 4.0) << "drift over the 9.5 m walked before";
      EXPECT_LT((e_anchored - (1 - correction) * e_free).norm(), 1e-12);
      const Eigen::Matrix3d R = a.X_WWmap.linear(), R_free = u.X_WWmap.linear();
      EXPECT_NEAR(std::atan2(R(1, 0), R(0, 0)), (1 - correction) * std::atan2(R_free(1, 0), R_free(0, 0)),
                  1e-12);
    }
    EXPECT_TRUE(relocked);
    EXPECT_EQ(anchored.relocks(), 1);
    EXPECT_EQ(anchored.anchors(), 1) << "standing at the far end stores nothing: it never stood there";
  }
}

// The same with an error stored away from the origin: stand at A (the origin), walk to B and stand
// (B stored with the error of that moment, E_B), walk on to C and back to B. At the sample that
// re-enters B the error at the head and the yaw move half of the way from the unanchored model's
// to E_B's (both evaluated at the head), the yaw the short way round.
TEST(SlamModel, ReMatchingMovesTheErrorTowardTheOneStoredThere) {
  SlamConfig c = DriftOnly(8);
  c.anchor_relock_correction = 0.5;
  SlamConfig free = c;
  free.anchor_radius_m = 0;
  SlamModel anchored(c), unanchored(free);
  const Eigen::Vector3d A(0, 0, 1.7), B(4, 0, 1.7), C(4, 4, 1.7);
  std::vector<Eigen::Vector3d> path = {A};
  auto walk = [&path](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
    const int n = static_cast<int>(std::ceil((to - from).norm() / (0.8 / 60)));
    for (int i = 1; i <= n; ++i) path.push_back(from + (to - from) * (static_cast<double>(i) / n));
  };
  walk(A, B);
  for (int i = 0; i < 60; ++i) path.push_back(B);  // a second standing at B
  walk(B, C);
  walk(C, B);
  auto yaw = [](const Eigen::Isometry3d& E) { return std::atan2(E.linear()(1, 0), E.linear()(0, 0)); };
  double t = 0;
  std::optional<Eigen::Isometry3d> E_B;
  bool checked = false;
  for (const Eigen::Vector3d& p : path) {
    const SlamSample a = anchored.Step(HeadAt(p), t);
    const SlamSample u = unanchored.Step(HeadAt(p), t);
    t += 1.0 / 60;
    if (!E_B && p == B) E_B = u.X_WWmap;  // the first sample standing at B stores it
    if (anchored.relocks() == 0) {
      EXPECT_TRUE(a.X_WWmap.isApprox(u.X_WWmap, 0));
      continue;
    }
    ASSERT_TRUE(E_B.has_value());
    const Eigen::Vector3d e_free = u.X_WWmap * p - p, e_B = *E_B * p - p, e = a.X_WWmap * p - p;
    EXPECT_GT((e_free - e_B).norm(), 0.01 * 7.0) << "8 m walked since B was stored";
    EXPECT_GT(e_B.norm(), 0.01 * 3.0) << "B was stored 4 m from the origin";
    EXPECT_LT((e - (e_B + 0.5 * (e_free - e_B))).norm(), 1e-12);
    EXPECT_NEAR(yaw(a.X_WWmap), yaw(*E_B) + 0.5 * (yaw(u.X_WWmap) - yaw(*E_B)), 1e-12);
    checked = true;
    break;
  }
  EXPECT_TRUE(checked);
  EXPECT_EQ(anchored.anchors(), 2) << "the origin and B; C was never stood at";
}

// Per-session drift: the band is the 5-95 % range of the drawn rates, the median the configured
// value; without a spread every session gets the median; the draw changes nothing else.
TEST(SlamConfig, SessionDriftIsDrawnFromTheBand) {
  const SlamConfig shipped = LoadSlamConfigFile(orbed::SourceTreePath(kDefaultSlamConfigRelativePath));
  std::vector<double> drawn;
  for (std::uint64_t seed = 1; seed <= 4000; ++seed) {
    const SlamConfig c = SessionSlamConfig(shipped, seed);
    EXPECT_EQ(c.seed, seed);
    drawn.push_back(c.drift_fraction_of_distance);
  }
  EXPECT_EQ(SessionSlamConfig(shipped, 17).drift_fraction_of_distance,
            SessionSlamConfig(shipped, 17).drift_fraction_of_distance);
  std::sort(drawn.begin(), drawn.end());
  const double p05 = drawn[200], p50 = drawn[2000], p95 = drawn[3800];
  std::printf("per-session drift: 5 %% %.4f, median %.4f, 95 %% %.4f\n", p05, p50, p95);
  EXPECT_NEAR(p05, shipped.drift_band_min_fraction, 0.1 * shipped.drift_band_min_fraction);
  EXPECT_NEAR(p95, shipped.drift_band_max_fraction, 0.1 * shipped.drift_band_max_fraction);
  EXPECT_NEAR(p50, shipped.drift_fraction_of_distance, 0.05 * shipped.drift_fraction_of_distance);
  SlamConfig fixed = shipped;
  fixed.drift_session_log_sigma = 0;
  const SlamConfig one = SessionSlamConfig(fixed, 99);
  EXPECT_EQ(one.drift_fraction_of_distance, shipped.drift_fraction_of_distance);
  EXPECT_EQ(one.drift_yaw_deg_per_m, shipped.drift_yaw_deg_per_m);
  EXPECT_EQ(one.anchor_radius_m, shipped.anchor_radius_m);
}

TEST(SlamModel, NoDriftWhileStandingAndMapStartsOnWorld) {
  SlamConfig c;
  c.tracking_loss_rate_per_min = 0;
  HeadTrajectoryConfig stand;
  stand.speed_m_per_s = 1;
  stand.p_W_look_at = Eigen::Vector3d(0, 0, 1.2);
  stand.waypoints = {{"here", {1.5, -1, 1.7}, 30.0, {}}};
  const std::vector<SlamSample> s = SimulateWalk(HeadTrajectory(stand), c, 20.0);
  for (const auto& x : s) {
    EXPECT_TRUE(x.X_WWmap.isApprox(Eigen::Isometry3d::Identity(), 1e-12));
    EXPECT_LT((x.X_WH_est.translation() - x.X_WH_true.translation()).norm(), 6 * c.jitter_translation_std_m);
  }
}

TEST(SlamModel, TrackingLossFreezesAndRelocalizes) {
  SlamConfig c;
  c.seed = 3;
  c.tracking_loss_rate_per_min = 20;  // frequent, to see every state
  c.lost_probability = 0.5;
  const std::vector<SlamSample> s = SimulateWalk(HeadTrajectory(RectangleWalk()), c, 120.0);
  int counts[4] = {0, 0, 0, 0};
  for (std::size_t k = 1; k < s.size(); ++k) {
    ++counts[static_cast<int>(s[k].state)];
    if (s[k].state == TrackingState::kLost) {
      // The device holds its last pose while lost.
      EXPECT_TRUE(s[k].X_WH_est.isApprox(s[k - 1].X_WH_est, 1e-15));
    }
    if (s[k].state == TrackingState::kRelocalized) {
      // One sample only, and always after a degraded state.
      EXPECT_NE(s[k - 1].state, TrackingState::kTracking);
      if (k + 1 < s.size()) {
        EXPECT_NE(s[k + 1].state, TrackingState::kRelocalized);
      }
    }
    EXPECT_EQ(s[k].seq, static_cast<std::int64_t>(k));
  }
  EXPECT_GT(counts[0], 0);
  EXPECT_GT(counts[1], 0);
  EXPECT_GT(counts[2], 0);
  EXPECT_GT(counts[3], 10);  // ~20/min over 2 min, most episodes end in a relocalization
}

// A forced fault, counted by hand: LOST for 0.5 s at 60 Hz is 30 LOST samples (the estimate
// frozen), then one RELOCALIZED sample whose map error is exactly the given jump (no drift, so
// nothing to shrink), then TRACKING. Before the fault the model is the one never forced.
TEST(SlamModel, ForcedFaultHoldsItsSamplesThenJumps) {
  SlamConfig c;
  c.tracking_loss_rate_per_min = 0;
  c.drift_fraction_of_distance = c.drift_yaw_deg_per_m = 0;
  HeadTrajectoryConfig stand;
  stand.speed_m_per_s = 1;
  stand.p_W_look_at = Eigen::Vector3d(0, 0, 1.2);
  stand.waypoints = {{"here", {1.5, -1, 1.7}, 30.0, {}}};
  const HeadTrajectory walk(stand);
  SlamModel forced(c), plain(c);
  ForcedFault fault;
  fault.state = TrackingState::kLost;
  fault.duration_s = 0.5;
  fault.jump_W_m = Eigen::Vector3d(0.02, -0.01, 0);
  fault.jump_yaw_deg = 1.0;
  const double dt = 1.0 / c.rate_hz;
  std::vector<SlamSample> s;
  for (int k = 0; k < 40; ++k) {
    if (k == 5) {
      forced.Force(fault);
      EXPECT_TRUE(forced.forcing());
    }
    s.push_back(forced.Step(walk.X_WH(k * dt), k * dt));
    const SlamSample p = plain.Step(walk.X_WH(k * dt), k * dt);
    if (k < 5) {
      EXPECT_TRUE(s.back().X_WH_est.isApprox(p.X_WH_est, 0));
    }
  }
  for (int k = 0; k < 40; ++k) {
    const TrackingState expected = k < 5     ? TrackingState::kTracking
                                   : k < 35  ? TrackingState::kLost
                                   : k == 35 ? TrackingState::kRelocalized
                                             : TrackingState::kTracking;
    EXPECT_EQ(s[k].state, expected) << "sample " << k;
    if (expected == TrackingState::kLost) {
      EXPECT_TRUE(s[k].X_WH_est.isApprox(s[4].X_WH_est, 0));
    }
  }
  EXPECT_FALSE(forced.forcing());
  // The jump about the head: yaw about the vertical through p_WH, then the translation.
  const Eigen::Vector3d p_WH = s[35].X_WH_true.translation();
  Eigen::Isometry3d jump = Eigen::Isometry3d::Identity();
  jump.linear() = Eigen::AngleAxisd(1.0 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  jump.translation() = p_WH - jump.linear() * p_WH + Eigen::Vector3d(0.02, -0.01, 0);
  EXPECT_TRUE(s[35].X_WWmap.isApprox(jump, 1e-12));
  EXPECT_TRUE(s[39].X_WWmap.isApprox(jump, 1e-12));
  // A "fault" that keeps tracking, or lasts no time, is refused.
  fault.state = TrackingState::kTracking;
  EXPECT_THROW(forced.Force(fault), std::invalid_argument);
  fault.state = TrackingState::kLimited;
  fault.duration_s = 0;
  EXPECT_THROW(forced.Force(fault), std::invalid_argument);
}

TEST(SlamModel, RandomLossesCanBeTurnedOff) {
  SlamConfig c;
  c.tracking_loss_rate_per_min = 60;
  SlamModel model(c);
  model.set_random_losses(false);
  const HeadTrajectory walk(RectangleWalk());
  for (int k = 0; k < 60 * 60; ++k) {
    EXPECT_EQ(model.Step(walk.X_WH(k / 60.0), k / 60.0).state, TrackingState::kTracking) << k;
  }
}

TEST(SlamConfig, FaultSchedule) {
  auto parse = [](const std::string& text) {
    return ParseSlamConfig(YamlFields::LoadString(text, "f.yaml")["slam"], "f.yaml");
  };
  const SlamConfig c = parse(
      "slam:\n  faults:\n"
      "    - {session: s1, trial: 2, at_s: 1.5, state: lost, duration_s: 2, jump: {position_m: [0.03, 0, 0], "
      "yaw_deg: -1}}\n"
      "    - {trial: 2, at_s: 3.6, state: limited, duration_s: 0.5}\n");
  ASSERT_EQ(c.faults.size(), 2u);
  EXPECT_EQ(c.faults[0].session_id, "s1");
  EXPECT_EQ(c.faults[0].trial_index, 2);
  EXPECT_EQ(c.faults[0].timed.at_s, 1.5);
  EXPECT_EQ(c.faults[0].timed.fault.state, TrackingState::kLost);
  EXPECT_EQ(c.faults[0].timed.fault.duration_s, 2.0);
  EXPECT_EQ(c.faults[0].timed.fault.jump_W_m, Eigen::Vector3d(0.03, 0, 0));
  EXPECT_EQ(c.faults[0].timed.fault.jump_yaw_deg, -1.0);
  EXPECT_EQ(c.faults[1].timed.fault.state, TrackingState::kLimited);
  EXPECT_EQ(c.faults[1].timed.fault.jump_W_m, Eigen::Vector3d::Zero());
  EXPECT_TRUE(c.faults[0].AppliesTo("s1", 2));
  EXPECT_FALSE(c.faults[0].AppliesTo("s2", 2));
  EXPECT_FALSE(c.faults[0].AppliesTo("s1", 1));
  EXPECT_TRUE(c.faults[1].AppliesTo("s2", 2));  // no session: every session
  EXPECT_TRUE(SlamConfig{}.faults.empty());

  auto error = [&](const std::string& text) {
    try {
      parse(text);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Overlapping faults of one trial: the second starts before the first one's end (1.5 + 2).
  EXPECT_NE(error("slam:\n  faults:\n"
                  "    - {session: s1, trial: 2, at_s: 1.5, state: lost, duration_s: 2}\n"
                  "    - {trial: 2, at_s: 3.5, state: lost, duration_s: 1}\n")
                .find("f.yaml:4: slam.faults[1].at_s: after the end of the trial's earlier fault"),
            std::string::npos);
  // Another trial may overlap.
  EXPECT_EQ(error("slam:\n  faults:\n"
                  "    - {trial: 2, at_s: 1.5, state: lost, duration_s: 2}\n"
                  "    - {trial: 3, at_s: 1.5, state: lost, duration_s: 2}\n"),
            "no error");
  EXPECT_NE(error("slam:\n  faults:\n    - {trial: 0, at_s: 1, state: tracking, duration_s: 1}\n")
                .find("slam.faults[0].state: expected"),
            std::string::npos);
  EXPECT_NE(error("slam:\n  faults:\n    - {trial: 0, at_s: 1, state: lost, duration_s: 61}\n")
                .find("slam.faults[0].duration_s"),
            std::string::npos);
  EXPECT_NE(
      error("slam:\n  faults:\n    - {at_s: 1, state: lost, duration_s: 1}\n").find("slam.faults[0].trial"),
      std::string::npos);
  EXPECT_NE(error("slam:\n  faults:\n    - {trial: 0, at_s: 1, state: lost, duration_s: 1, when: 3}\n")
                .find("unknown key"),
            std::string::npos);
}

// The hologram relation X_WV_apparent = X_WH_true · X_WH_est⁻¹ · X_WV and its consequences.
TEST(SlamModel, HologramRelation) {
  SlamConfig c;
  c.seed = 11;
  c.drift_fraction_of_distance = 0.014;
  c.drift_yaw_deg_per_m = 0.5;
  c.tracking_loss_rate_per_min = 2;
  const std::vector<SlamSample> s = SimulateWalk(HeadTrajectory(RectangleWalk()), c, 60.0);
  const SlamSample& x = s.back();
  ASSERT_GT((x.X_WH_true.translation() - x.X_WH_est.translation()).norm(), 0.01);  // a real error

  // (1) Head-locked content (placed relative to the estimated head) is exactly where it should be
  //     relative to the true head, whatever the tracking error.
  Eigen::Isometry3d X_HV = Eigen::Isometry3d::Identity();
  X_HV.translation() = Eigen::Vector3d(0.1, 0.05, 1.2);
  X_HV.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Isometry3d head_locked = ApparentPose(x.X_WH_true, x.X_WH_est, x.X_WH_est * X_HV);
  EXPECT_TRUE(head_locked.isApprox(x.X_WH_true * X_HV, 1e-12));

  // (2) The device's overlay in its own camera image (drawn with X_WC_est) falls where the true
  //     camera sees the apparent hologram.
  const geometry::Intrinsics in = geometry::Intrinsics::HoloLensPv();
  Eigen::Isometry3d X_WV = Eigen::Isometry3d::Identity();
  X_WV.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  const Eigen::Isometry3d apparent = ApparentPose(x.X_WH_true, x.X_WH_est, X_WV);
  const geometry::CameraMatrix P_est = geometry::MakeCameraMatrix(in.K(), x.X_WC_est);
  const geometry::CameraMatrix P_true = geometry::MakeCameraMatrix(in.K(), x.X_WC_true);
  for (const Eigen::Vector3d& p_V : {Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(0.1, -0.2, 1.1)}) {
    Eigen::Vector2d u_device, u_true;
    ASSERT_TRUE(geometry::Project(P_est, X_WV * p_V, &u_device));
    ASSERT_TRUE(geometry::Project(P_true, apparent * p_V, &u_true));
    EXPECT_LT((u_device - u_true).norm(), 1e-6);
  }

  // (3) With a purely translational error (no yaw drift, no jitter, no relocalization), every
  //     hologram point is shifted by the same p_WH_true − p_WH_est.
  SlamConfig t = c;
  t.drift_yaw_deg_per_m = 0;
  t.jitter_rotation_std_deg = 0;
  t.jitter_translation_std_m = 0;
  t.tracking_loss_rate_per_min = 0;
  const SlamSample y = SimulateWalk(HeadTrajectory(RectangleWalk()), t, 60.0).back();
  const Eigen::Vector3d shift = y.X_WH_true.translation() - y.X_WH_est.translation();
  ASSERT_GT(shift.norm(), 0.01);
  const Eigen::Isometry3d moved = ApparentPose(y.X_WH_true, y.X_WH_est, X_WV);
  for (const Eigen::Vector3d& p_V : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3, 0.2, 1.3)}) {
    EXPECT_LT((moved * p_V - X_WV * p_V - shift).norm(), 1e-12);
  }
  EXPECT_TRUE(moved.linear().isApprox(X_WV.linear(), 1e-12));
}

TEST(SlamModel, SameSeedSameWalk) {
  SlamConfig c;
  c.seed = 5;
  const HeadTrajectory walk(RectangleWalk());
  const auto a = SimulateWalk(walk, c, 10.0);
  const auto b = SimulateWalk(walk, c, 10.0);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a.back().X_WH_est.isApprox(b.back().X_WH_est, 0));
  c.seed = 6;
  EXPECT_FALSE(SimulateWalk(walk, c, 10.0).back().X_WH_est.isApprox(a.back().X_WH_est, 1e-9));
}

// Every key `file` sets is documented in the header's @code{.yaml} block.
void ExpectDocumented(const YAML::Node& doc, const std::string& file, const std::string& header) {
  const std::set<std::string> documented = YamlFields::KeyPaths(doc);
  for (const std::string& k : YamlFields::KeyPaths(YamlFields::LoadFile(file))) {
    EXPECT_TRUE(documented.count(k)) << k << ": set in " << file << ", not documented in " << header;
  }
}

void ExpectSame(const SlamConfig& a, const SlamConfig& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.rate_hz, b.rate_hz);
  EXPECT_TRUE(a.X_HC.isApprox(b.X_HC, 0)) << a.X_HC.matrix() << "\n" << b.X_HC.matrix();
  EXPECT_EQ(a.jitter_translation_std_m, b.jitter_translation_std_m);
  EXPECT_EQ(a.jitter_rotation_std_deg, b.jitter_rotation_std_deg);
  EXPECT_EQ(a.drift_fraction_of_distance, b.drift_fraction_of_distance);
  EXPECT_EQ(a.drift_session_log_sigma, b.drift_session_log_sigma);
  EXPECT_EQ(a.anchor_radius_m, b.anchor_radius_m);
  EXPECT_EQ(a.anchor_relock_correction, b.anchor_relock_correction);
  EXPECT_EQ(a.drift_yaw_deg_per_m, b.drift_yaw_deg_per_m);
  EXPECT_EQ(a.drift_direction_correlation_m, b.drift_direction_correlation_m);
  EXPECT_EQ(a.drift_band_min_fraction, b.drift_band_min_fraction);
  EXPECT_EQ(a.drift_band_max_fraction, b.drift_band_max_fraction);
  EXPECT_EQ(a.tracking_loss_rate_per_min, b.tracking_loss_rate_per_min);
  EXPECT_EQ(a.limited_mean_s, b.limited_mean_s);
  EXPECT_EQ(a.limited_drift_multiplier, b.limited_drift_multiplier);
  EXPECT_EQ(a.lost_probability, b.lost_probability);
  EXPECT_EQ(a.lost_mean_s, b.lost_mean_s);
  EXPECT_EQ(a.relocalization_correction, b.relocalization_correction);
  EXPECT_EQ(a.jump_translation_std_m, b.jump_translation_std_m);
  EXPECT_EQ(a.jump_yaw_std_deg, b.jump_yaw_std_deg);
}

// The defaults live in three places that must agree: slam_model.h's @code{.yaml} block, SlamConfig's
// member initializers and config/slam.yaml. Fails when one is edited without the others.
TEST(SlamConfig, HeaderStructAndShippedFileAgree) {
  const std::string header = orbed::SourceTreePath("hmd_emulator/slam_model.h");
  const std::string file = orbed::SourceTreePath(kDefaultSlamConfigRelativePath);
  const YAML::Node doc = YamlFields::LoadDocBlock(header);
  ExpectDocumented(doc, file, header);
  ExpectSame(ParseSlamConfig(doc["slam"], header), SlamConfig{}, "header vs SlamConfig");
  ExpectSame(LoadSlamConfigFile(file), SlamConfig{}, "config/slam.yaml vs SlamConfig");
}

// head_trajectory.h shows the shipped walk; HeadTrajectoryConfig starts from its speed and target.
TEST(HeadTrajectoryConfig, HeaderStructAndShippedWalkAgree) {
  const std::string header = orbed::SourceTreePath("hmd_emulator/head_trajectory.h");
  const std::string file = orbed::SourceTreePath("hmd_emulator/config/viraal_walk.yaml");
  const YAML::Node doc = YamlFields::LoadDocBlock(header);
  ExpectDocumented(doc, file, header);
  const HeadTrajectoryConfig d;
  const HeadTrajectoryConfig from_doc = ParseHeadTrajectory(doc["head_trajectory"], header);
  const HeadTrajectoryConfig shipped = LoadHeadTrajectoryFile(file);
  for (const HeadTrajectoryConfig* c : {&from_doc, &shipped}) {
    EXPECT_EQ(c->speed_m_per_s, d.speed_m_per_s);
    EXPECT_EQ(c->p_W_look_at, d.p_W_look_at);
    EXPECT_EQ(c->loop, d.loop);
  }
  ASSERT_EQ(from_doc.waypoints.size(), shipped.waypoints.size());
  for (std::size_t i = 0; i < shipped.waypoints.size(); ++i) {
    EXPECT_EQ(from_doc.waypoints[i].name, shipped.waypoints[i].name);
    EXPECT_EQ(from_doc.waypoints[i].p_WH, shipped.waypoints[i].p_WH);
    EXPECT_EQ(from_doc.waypoints[i].dwell_s, shipped.waypoints[i].dwell_s);
    EXPECT_EQ(from_doc.waypoints[i].p_W_look_at.has_value(), shipped.waypoints[i].p_W_look_at.has_value());
  }
  // The documented defaults of the optional keys.
  const HeadTrajectoryConfig bare = ParseHeadTrajectory(
      YamlFields::LoadString(
          "speed_m_per_s: 1\nlook_at_m: [0, 0, 1]\nwaypoints: [{position_m: [2, 0, 1.7]}]\n", "bare.yaml"),
      "bare.yaml");
  EXPECT_EQ(bare.loop, d.loop);
  EXPECT_EQ(bare.waypoints.at(0).dwell_s, HeadWaypoint{}.dwell_s);
  EXPECT_EQ(bare.waypoints.at(0).name, "waypoint0");
  EXPECT_FALSE(bare.waypoints.at(0).p_W_look_at.has_value());
}

TEST(SlamConfig, ErrorsNameFileKeyAndExpectation) {
  auto parse = [](const std::string& text) {
    return ParseSlamConfig(YamlFields::LoadString(text, "bad.yaml")["slam"], "bad.yaml");
  };
  try {
    parse("slam:\n  drift:\n    fraction_of_distance: -1\n");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "bad.yaml:3: slam.drift.fraction_of_distance: expected a number in [0, 0.2], got '-1'");
  }
  try {
    parse("slam:\n  jiter: {}\n");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:2: slam.jiter: unknown key; expected one of:"),
              std::string::npos)
        << e.what();
  }
  try {
    ParseHeadTrajectory(
        YamlFields::LoadString("speed_m_per_s: 1\nlook_at_m: [0, 0]\nwaypoints: []\n", "w.yaml"), "w.yaml");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "w.yaml:2: head_trajectory.look_at_m: expected a list of 3 numbers [m]");
  }
}

}  // namespace
}  // namespace orbed::hmd
