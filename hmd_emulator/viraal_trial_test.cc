// Tracking faults while the emulated person aligns (viraal_trial.h). The SLAM model is made exact
// (no jitter, no drift, no drawn losses: the map is the world until a forced relocalization jump),
// so the oracles are worked out from the pieces: the fault-free trial, the person's own alignment
// (EmulatedUser::Align) from the pose they had reached, with what they see after the jump, and the
// hologram relation (ApparentPose).
#include "hmd_emulator/viraal_trial.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <cmath>

#include "base/source_paths.h"
#include "geometry/triangulation.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

struct Fixture {
  TrialSetup setup;
  SlamConfig slam;
  EmulatedUser user{UserConfig{}};
  Eigen::Isometry3d X_WV_start;
  static constexpr std::uint64_t kTrialSeed = 11;

  Fixture() {
    const sim::Scene scene = sim::LoadSceneFile(orbed::SourceDir() + "/" + sim::kDefaultSceneRelativePath);
    const sim::RobotModel robot =
        sim::LoadRobotForScene(orbed::SourceDir() + "/" + sim::RobotModel::kDefaultUrdfRelativePath, scene);
    setup.X_WR = scene.X_WR;
    setup.p_RQ =
        RobotModelPoints(robot, sim::DegToRad((Eigen::VectorXd(7) << 0, 30, 0, -60, 0, 45, 0).finished()));
    setup.walk = LoadHeadTrajectoryFile(orbed::SourceDir() + "/hmd_emulator/config/viraal_walk.yaml");
    setup.capture_waypoints = {"foot_end"};
    setup.align_waypoint = "head_end";
    setup.intrinsics = geometry::Intrinsics::HoloLensPv();
    slam.jitter_translation_std_m = slam.jitter_rotation_std_deg = 0;
    slam.drift_fraction_of_distance = slam.drift_yaw_deg_per_m = 0;
    slam.tracking_loss_rate_per_min = 0;
    X_WV_start = user.StartPose(scene.X_WR);
  }
  TrialOutcome Run(const std::vector<TimedFault>& faults, int max_repeats = 2) const {
    TrialSetup s = setup;
    s.faults = faults;
    s.max_repeats = max_repeats;
    return RunTrial(s, slam, user, X_WV_start, kTrialSeed);
  }
  // What the person sees with the head at `sample` (the displays as the trial captured them).
  ViewingContext Context(const TrialOutcome& o, const SlamSample& sample) const {
    return TrialViewingContext(setup, sample, o.at_capture);
  }
};

TimedFault Fault(double at_s, TrackingState state, double duration_s,
                 const Eigen::Vector3d& jump_W_m = {0, 0, 0}) {
  TimedFault f;
  f.at_s = at_s;
  f.fault.state = state;
  f.fault.duration_s = duration_s;
  f.fault.jump_W_m = jump_W_m;
  return f;
}

// The jump as the model applies it at the head (yaw 0: a translation).
Eigen::Isometry3d Translation(const Eigen::Vector3d& t) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = t;
  return X;
}

TEST(TrackingFaults, NoneWithoutASchedule) {
  const Fixture f;
  const TrialOutcome o = f.Run({});
  EXPECT_EQ(o.faults.losses, 0);
  EXPECT_EQ(o.faults.relocalizations, 0);
  EXPECT_EQ(o.faults.wait_s, 0);
  EXPECT_EQ(o.faults.repeats, 0);
  EXPECT_TRUE(o.at_end.X_WH_est.isApprox(o.at_alignment.X_WH_est, 0));
  EXPECT_EQ(o.at_end.seq, o.at_alignment.seq);
  // The exact model: the map is the world, the hologram appears where it is placed.
  EXPECT_NEAR(o.augmentation.translation_error_m, o.registration.translation_error_m, 1e-12);
}

// LOST for 2 s, 1 s into the alignment, with no jump: the person waits and carries on; the trial is
// the fault-free one, 2 s (120 samples at 60 Hz) longer.
TEST(TrackingFaults, LostWithoutJumpAddsExactlyTheWait) {
  const Fixture f;
  const TrialOutcome base = f.Run({});
  ASSERT_GT(base.alignment.duration_s, 1.0);
  const TrialOutcome o = f.Run({Fault(1.0, TrackingState::kLost, 2.0)});
  EXPECT_TRUE(o.alignment.X_WV.isApprox(base.alignment.X_WV, 0));
  EXPECT_NEAR(o.alignment.duration_s, base.alignment.duration_s + 2.0, 1e-9);
  EXPECT_EQ(o.faults.losses, 1);
  EXPECT_EQ(o.faults.relocalizations, 1);
  EXPECT_NEAR(o.faults.wait_s, 2.0, 1e-9);
  EXPECT_EQ(o.faults.repeats, 0);
  ASSERT_EQ(o.faults.met.size(), 1u);
  EXPECT_NEAR(o.faults.met[0].at_s, 1.0, 1e-9);
  EXPECT_EQ(o.at_end.state, TrackingState::kRelocalized);
  EXPECT_NEAR(o.at_end.t_s - o.at_alignment.t_s, 3.0, 1e-9);
  EXPECT_NEAR(o.registration.translation_error_m, base.registration.translation_error_m, 1e-12);
  EXPECT_NEAR(o.augmentation.translation_error_m, base.augmentation.translation_error_m, 1e-12);
  // LIMITED the same: the state does not matter to a person who waits.
  const TrialOutcome limited = f.Run({Fault(1.0, TrackingState::kLimited, 2.0)});
  EXPECT_TRUE(limited.alignment.X_WV.isApprox(base.alignment.X_WV, 0));
  EXPECT_NEAR(limited.alignment.duration_s, base.alignment.duration_s + 2.0, 1e-9);
}

// A 5 cm jump 10 s into the alignment: the person sees the hologram move (86 arcmin at ~2 m),
// re-does the alignment from where they were at 10 s with what they see after the jump, and ends
// with a pose of the jumped map. (AR only here: a display captured before the jump still shows the
// overlay drawn with the old map and pulls the other way; the next test has one.)
TEST(TrackingFaults, JumpMakesThePersonRedoTheAlignmentInTheNewMap) {
  Fixture f;
  f.setup.capture_waypoints.clear();
  const Eigen::Vector3d jump_W_m(0.05, 0, 0);
  const TrialOutcome base = f.Run({});
  ASSERT_GT(base.alignment.duration_s, 10.0);
  const TrialOutcome o = f.Run({Fault(10.0, TrackingState::kLost, 2.0, jump_W_m)});
  EXPECT_EQ(o.faults.losses, 1);
  EXPECT_EQ(o.faults.repeats, 1);
  EXPECT_NEAR(o.faults.wait_s, 2.0, 1e-9);
  // After the jump the device believes the head is at J⁻¹ · X_WH_true.
  const Eigen::Isometry3d J = Translation(jump_W_m);
  EXPECT_TRUE(o.at_end.X_WH_est.isApprox(J.inverse() * o.at_alignment.X_WH_true, 1e-12));
  // The oracle from the pieces: the second attempt.
  ViewingContext after = f.Context(o, o.at_alignment);
  after.X_WH_est = J.inverse() * o.at_alignment.X_WH_true;
  const AlignmentResult redo =
      f.user.Align(after, f.setup.p_RQ, base.alignment.X_WV_at(10.0), Fixture::kTrialSeed);
  EXPECT_TRUE(o.alignment.X_WV.isApprox(redo.X_WV, 1e-12));
  EXPECT_NEAR(o.alignment.duration_s, 10.0 + 2.0 + redo.duration_s, 1e-9);
  const PoseError augmentation =
      EvaluatePose(J * redo.X_WV, f.setup.X_WR, f.setup.p_RQ, o.at_alignment.X_WH_true.translation());
  EXPECT_NEAR(o.augmentation.translation_error_m, augmentation.translation_error_m, 1e-9);
  // Physically: the person aligned what they saw, so the hologram appears on the robot about as
  // well as without the fault, and in map coordinates it is off by about the jump.
  EXPECT_LT(o.augmentation.translation_error_m, base.augmentation.translation_error_m + 0.01);
  EXPECT_GT(o.registration.translation_error_m, 0.03);
}

// With a display captured before the jump (stamped with the old map), the re-done alignment lands
// between the two maps: the jump is partly re-aligned, partly left in the augmentation error.
TEST(TrackingFaults, AStaleDisplayHoldsThePersonToTheOldMap) {
  const Fixture f;
  ASSERT_EQ(f.setup.capture_waypoints.size(), 1u);
  const Eigen::Vector3d jump_W_m(0.05, 0, 0);
  const TrialOutcome o = f.Run({Fault(10.0, TrackingState::kLost, 2.0, jump_W_m)});
  EXPECT_EQ(o.faults.repeats, 1);
  const PoseError old_map =
      EvaluatePose(o.alignment.X_WV, f.setup.X_WR, f.setup.p_RQ, o.at_alignment.X_WH_true.translation());
  EXPECT_GT(o.augmentation.translation_error_m, 0.01);
  EXPECT_LT(o.augmentation.translation_error_m, 0.05);
  EXPECT_LT(old_map.translation_error_m, 0.05);
}

// No repeats left: the person carries on, submits the pose of the old map, and the jump shows in
// the augmentation error.
TEST(TrackingFaults, WithoutRepeatsTheJumpStaysInTheAugmentationError) {
  const Fixture f;
  const Eigen::Vector3d jump_W_m(0.05, 0, 0);
  const TrialOutcome base = f.Run({});
  const TrialOutcome o = f.Run({Fault(10.0, TrackingState::kLost, 2.0, jump_W_m)}, /*max_repeats=*/0);
  EXPECT_EQ(o.faults.repeats, 0);
  EXPECT_TRUE(o.alignment.X_WV.isApprox(base.alignment.X_WV, 0));
  EXPECT_NEAR(o.alignment.duration_s, base.alignment.duration_s + 2.0, 1e-9);
  const PoseError augmentation = EvaluatePose(Translation(jump_W_m) * base.alignment.X_WV, f.setup.X_WR,
                                              f.setup.p_RQ, o.at_alignment.X_WH_true.translation());
  EXPECT_NEAR(o.augmentation.translation_error_m, augmentation.translation_error_m, 1e-9);
  EXPECT_NEAR(o.registration.translation_error_m, base.registration.translation_error_m, 1e-12);
}

// Two jumps, one repeat allowed: the first is re-done (from 7 s on), the second, 1 s into the
// re-done attempt, is waited out and the attempt carried on.
TEST(TrackingFaults, RepeatsAreBounded) {
  const Fixture f;
  const TrialOutcome o = f.Run({Fault(5.0, TrackingState::kLost, 2.0, {0.05, 0, 0}),
                                Fault(8.0, TrackingState::kLimited, 1.0, {0, 0.05, 0})},
                               /*max_repeats=*/1);
  EXPECT_EQ(o.faults.losses, 2);
  EXPECT_EQ(o.faults.relocalizations, 2);
  EXPECT_EQ(o.faults.repeats, 1);
  EXPECT_NEAR(o.faults.wait_s, 3.0, 1e-9);
  ViewingContext after = f.Context(o, o.at_alignment);
  after.X_WH_est = Translation({0.05, 0, 0}).inverse() * o.at_alignment.X_WH_true;
  const TrialOutcome base = f.Run({});
  const AlignmentResult redo =
      f.user.Align(after, f.setup.p_RQ, base.alignment.X_WV_at(5.0), Fixture::kTrialSeed);
  ASSERT_GT(redo.duration_s, 1.0);  // the second fault falls inside the re-done attempt
  EXPECT_TRUE(o.alignment.X_WV.isApprox(redo.X_WV, 1e-12));
  EXPECT_NEAR(o.alignment.duration_s, 7.0 + redo.duration_s + 1.0, 1e-9);
}

// A fault scheduled after the person submitted does not happen to them.
TEST(TrackingFaults, AfterTheSubmissionNothingHappens) {
  const Fixture f;
  const TrialOutcome base = f.Run({});
  const TrialOutcome o =
      f.Run({Fault(base.alignment.duration_s + 1.0, TrackingState::kLost, 2.0, {0.05, 0, 0})});
  EXPECT_EQ(o.faults.losses, 0);
  EXPECT_TRUE(o.faults.met.empty());
  EXPECT_TRUE(o.alignment.X_WV.isApprox(base.alignment.X_WV, 0));
  EXPECT_EQ(o.alignment.duration_s, base.alignment.duration_s);
}

// The landmark annotation after the alignment (viraal_trial.h): each landmark triangulated from its
// rays, for one side.
Eigen::Vector3d Triangulated(const TrialOutcome& o, int landmark, bool hologram) {
  std::vector<Eigen::Vector3d> origins, directions;
  for (const AnnotationRay& a : o.annotation) {
    if (a.landmark != landmark || a.hologram != hologram) continue;
    origins.push_back(a.ray.origin_W);
    directions.push_back(a.ray.direction_W);
  }
  const geometry::TriangulationResult r = geometry::TriangulateRays(origins, directions);
  EXPECT_TRUE(r.valid) << r.reason;
  return r.p_W;
}

Fixture AnnotatingFixture(double pointing_std_deg) {
  Fixture f;
  const sim::Scene scene = sim::LoadSceneFile(orbed::SourceDir() + "/" + sim::kDefaultSceneRelativePath);
  const sim::RobotModel robot =
      sim::LoadRobotForScene(orbed::SourceDir() + "/" + sim::RobotModel::kDefaultUrdfRelativePath, scene);
  const std::vector<Eigen::Isometry3d> X_RL =
      robot.CalcLinkPoses(sim::DegToRad((Eigen::VectorXd(7) << 0, 30, 0, -60, 0, 45, 0).finished()));
  for (const char* link : {"iiwa_link_4", "iiwa_link_6", "iiwa_link_ee"}) {
    f.setup.p_RL.push_back(X_RL[robot.FindLink(link)].translation());
  }
  f.setup.annotation.pointing_std_deg = pointing_std_deg;
  return f;
}

// Two positions, each landmark real then hologram, in landmark order; the second position is the
// first turned by the view angle about the vertical through the landmarks' centroid.
TEST(LandmarkAnnotation, TwoRaysPerLandmarkAndSideInTheDocumentedOrder) {
  const Fixture f = AnnotatingFixture(0.2);
  const TrialOutcome o = f.Run({});
  ASSERT_EQ(o.annotation.size(), 12u);
  for (std::size_t k = 0; k < o.annotation.size(); ++k) {
    EXPECT_EQ(o.annotation[k].landmark, static_cast<int>((k % 6) / 2)) << k;
    EXPECT_EQ(o.annotation[k].hologram, k % 2 == 1) << k;
    EXPECT_NEAR(o.annotation[k].ray.direction_W.norm(), 1.0, 1e-12);
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : f.setup.p_RL) centroid += f.setup.X_WR * p / 3.0;
  Eigen::Vector3d a = o.annotation[0].ray.origin_W - centroid, b = o.annotation[6].ray.origin_W - centroid;
  a.z() = b.z() = 0;
  EXPECT_NEAR(std::acos(a.normalized().dot(b.normalized())) * 180 / M_PI, f.setup.annotation_view_angle_deg,
              1e-6);
  // The annotation comes after the alignment and draws from its own seed: the trial is unchanged.
  Fixture plain;
  const TrialOutcome without = plain.Run({});
  EXPECT_TRUE(without.annotation.empty());
  EXPECT_TRUE(o.alignment.X_WV.isApprox(without.alignment.X_WV, 0));
}

// A perfect perceiver (no pointing error) in an exact map measures the registration exactly: the
// triangulated landmarks are the real robot's and the hologram's link origins.
TEST(LandmarkAnnotation, PerfectPerceiverInAnExactMapMeasuresTheTruth) {
  const Fixture f = AnnotatingFixture(0.0);
  const TrialOutcome o = f.Run({});
  for (int l = 0; l < 3; ++l) {
    EXPECT_LT((Triangulated(o, l, false) - f.setup.X_WR * f.setup.p_RL[l]).norm(), 1e-9) << l;
    EXPECT_LT((Triangulated(o, l, true) - o.alignment.X_WV * f.setup.p_RL[l]).norm(), 1e-9) << l;
  }
}

// The same perceiver after a relocalization jump J of the map that they did not re-align for: the
// measurement is made in the headset's own map, so each pair's difference is the truth's difference
// plus J (the hologram appears moved by J, the measurement sees exactly that, not the registration).
TEST(LandmarkAnnotation, PerfectPerceiverMeasuresTheViewNotTheMap) {
  const Fixture f = AnnotatingFixture(0.0);
  const Eigen::Vector3d jump_W_m(0.05, -0.02, 0);
  const TrialOutcome o = f.Run({Fault(10.0, TrackingState::kLost, 2.0, jump_W_m)}, /*max_repeats=*/0);
  ASSERT_EQ(o.faults.losses, 1);
  for (int l = 0; l < 3; ++l) {
    const Eigen::Vector3d measured = Triangulated(o, l, true) - Triangulated(o, l, false);
    const Eigen::Vector3d truth = o.alignment.X_WV * f.setup.p_RL[l] - f.setup.X_WR * f.setup.p_RL[l];
    EXPECT_LT((measured - (truth + jump_W_m)).norm(), 1e-9) << l;
  }
}

// A person's pointing error scatters the landmarks (at a few metres, by millimetres to centimetres).
TEST(LandmarkAnnotation, PointingErrorScattersTheLandmarks) {
  const Fixture f = AnnotatingFixture(0.2);
  const TrialOutcome o = f.Run({});
  for (int l = 0; l < 3; ++l) {
    const double off_m = (Triangulated(o, l, false) - f.setup.X_WR * f.setup.p_RL[l]).norm();
    EXPECT_GT(off_m, 1e-4) << l;
    EXPECT_LT(off_m, 0.2) << l;
  }
}

// The session's one map (SessionMapAtTrial). With a drift along one fixed direction (no jitter,
// no yaw, no losses, a direction that does not decorrelate), the map error at the head is the drift
// rate times the path walked since the map began, or since the place was last re-matched: the
// oracles below are that product.
struct SessionFixture : Fixture {
  Eigen::Vector3d p_W_start{2.6, 0.3, 1.7};
  SessionFixture() {
    slam.drift_fraction_of_distance = 0.01;
    slam.drift_direction_correlation_m = 1e12;
  }
  // The head's position error when trial k starts aligning.
  Eigen::Vector3d ErrorAtAlignment(int k, SlamSample* sample = nullptr) const {
    double t0 = 0;
    SlamModel map = SessionMapAtTrial(setup, slam, p_W_start, k, &t0);
    const SlamSample s = WalkToAlignment(setup, t0, &map).at_alignment;
    if (sample) *sample = s;
    const Eigen::Vector3d p = s.X_WH_true.translation();
    return s.X_WWmap * p - p;
  }
};

TEST(SessionMap, TheDisplayIsNotCapturedWhereTheMapBegan) {
  const SessionFixture f;
  double t0 = 0;
  SlamModel map = SessionMapAtTrial(f.setup, f.slam, f.p_W_start, 0, &t0);
  const SlamSample capture = WalkToAlignment(f.setup, t0, &map).at_capture.at(0);
  const double leg_m = (f.setup.walk.waypoints.front().p_WH - f.p_W_start).norm();
  EXPECT_GT(leg_m, 1.0);
  EXPECT_NEAR(capture.path_m, leg_m, 1e-9);
  const Eigen::Vector3d p = capture.X_WH_true.translation();
  EXPECT_NEAR((capture.X_WWmap * p - p).norm(), 0.01 * leg_m, 1e-6);
  // Put on at the first waypoint instead, the capture is where the map began: no error at all.
  SessionFixture at_waypoint;
  at_waypoint.p_W_start = f.setup.walk.waypoints.front().p_WH;
  SlamModel map0 = SessionMapAtTrial(at_waypoint.setup, at_waypoint.slam, at_waypoint.p_W_start, 0, &t0);
  EXPECT_TRUE(WalkToAlignment(at_waypoint.setup, t0, &map0)
                  .at_capture.at(0)
                  .X_WWmap.isApprox(Eigen::Isometry3d::Identity(), 1e-15));
}

// A frame taken while tracking is lost has no pose to place it with: the display waits for TRACKING.
TEST(SessionMap, TheDisplayCapturesOnlyWhileTracking) {
  const SessionFixture f;
  SlamModel map(f.slam);
  ForcedFault lost;
  lost.state = TrackingState::kLost;
  lost.duration_s = 1.0;
  map.Force(lost);
  const WalkSamples w = WalkToAlignment(f.setup, 0.0, &map);
  EXPECT_EQ(w.at_capture.at(0).state, TrackingState::kTracking);
  // 60 LOST samples (t = 0 .. 59/60), the RELOCALIZED one at t = 1, the first TRACKING one after it.
  EXPECT_NEAR(w.at_capture.at(0).t_s, 61.0 / 60.0, 1e-9);
  EXPECT_EQ(w.relocalizations, 1);
}

TEST(SessionMap, WithoutStoredPlacesTheDriftAccumulatesOverTheSession) {
  SessionFixture f;
  f.slam.anchor_radius_m = 0;
  for (int k : {0, 1, 3}) {
    SlamSample s;
    const Eigen::Vector3d e = f.ErrorAtAlignment(k, &s);
    EXPECT_NEAR(e.norm(), 0.01 * s.path_m, 1e-5 * s.path_m) << "trial " << k;
    if (k == 3) {
      EXPECT_GT(s.path_m, 3 * 4.0) << "three walks and returns of more than 2 m each";
    }
  }
}

TEST(SessionMap, ComingBackToTheSamePlacesHoldsTheErrorOfTheFirstVisit) {
  SessionFixture f;
  f.slam.anchor_relock_correction = 1;
  const Eigen::Vector3d e0 = f.ErrorAtAlignment(0);
  const Eigen::Vector3d e1 = f.ErrorAtAlignment(1), e3 = f.ErrorAtAlignment(3);
  // Re-matched to the error stored at the alignment place, then the drift of the last radius walked.
  const double inside_m = f.slam.anchor_radius_m;
  EXPECT_NEAR((e1 - e0).norm(), 0.01 * inside_m, 0.01 * 0.02);
  EXPECT_LT((e3 - e1).norm(), 1e-6) << "the same walk from the same re-matched error";
  SessionFixture unanchored = f;
  unanchored.slam.anchor_radius_m = 0;
  EXPECT_GT((unanchored.ErrorAtAlignment(3) - unanchored.ErrorAtAlignment(1)).norm(), 0.01 * 2 * 4.0);
}

// A trial does not depend on what was asked before it: trial 4 made after trials 0-3 (on the maps the
// cache carried on) is trial 4 made first, on a map replayed from the start.
TEST(SessionMap, ATrialDoesNotDependOnWhatCameBefore) {
  SessionFixture f;
  f.slam = SlamConfig{};  // jitter, drift, yaw and drawn losses: everything random
  f.slam.seed = 3;
  SessionMapCache cache;
  double t = 0;
  for (int k = 0; k < 4; ++k) {
    const SlamModel map = SessionMapAtTrial(f.setup, f.slam, f.p_W_start, k, &t, &cache);
    RunTrialFrom(f.setup, map, t, f.user, f.X_WV_start, static_cast<std::uint64_t>(k));
  }
  double t_after = 0, t_first = 0;
  const SlamModel after = SessionMapAtTrial(f.setup, f.slam, f.p_W_start, 4, &t_after, &cache);
  const SlamModel first = SessionMapAtTrial(f.setup, f.slam, f.p_W_start, 4, &t_first);
  EXPECT_EQ(t_after, t_first);
  const TrialOutcome o1 = RunTrialFrom(f.setup, after, t_after, f.user, f.X_WV_start, 4);
  const TrialOutcome o2 = RunTrialFrom(f.setup, first, t_first, f.user, f.X_WV_start, 4);
  EXPECT_TRUE(o1.alignment.X_WV.isApprox(o2.alignment.X_WV, 0));
  EXPECT_TRUE(o1.at_end.X_WH_est.isApprox(o2.at_end.X_WH_est, 0));
  EXPECT_GT(t_first, 4 * 5.0) << "four earlier trials' walks";
}

TEST(SessionMap, TheCacheGivesTheReplaysMap) {
  SessionFixture f;
  f.slam = SlamConfig{};  // everything random, drawn tracking losses included
  f.slam.seed = 9;
  SessionMapCache cache;
  for (int k : {0, 1, 2, 5, 3, 3}) {
    SCOPED_TRACE(k);
    double t_cached = 0, t_replayed = 0;
    const SlamModel cached = SessionMapAtTrial(f.setup, f.slam, f.p_W_start, k, &t_cached, &cache);
    const SlamModel replayed = SessionMapAtTrial(f.setup, f.slam, f.p_W_start, k, &t_replayed);
    EXPECT_EQ(t_cached, t_replayed);
    EXPECT_TRUE(cached.X_WWmap().isApprox(replayed.X_WWmap(), 0));
    EXPECT_EQ(cached.relocks(), replayed.relocks());
    SlamModel a = cached, b = replayed;
    const WalkSamples wa = WalkToAlignment(f.setup, t_cached, &a),
                      wb = WalkToAlignment(f.setup, t_replayed, &b);
    EXPECT_TRUE(wa.at_alignment.X_WH_est.isApprox(wb.at_alignment.X_WH_est, 0))
        << "the random streams agree too";
  }
  // The cache now holds trial 3 of seed 9. A later trial of anything else is replayed, not carried on.
  auto expect_replayed = [&](const SlamConfig& slam, const Eigen::Vector3d& start, const TrialSetup& setup) {
    SessionMapCache c = cache;
    double t_c = 0, t_r = 0;
    const SlamModel from_cache = SessionMapAtTrial(setup, slam, start, 5, &t_c, &c);
    const SlamModel replayed = SessionMapAtTrial(setup, slam, start, 5, &t_r);
    EXPECT_EQ(t_c, t_r);
    EXPECT_TRUE(from_cache.X_WWmap().isApprox(replayed.X_WWmap(), 0));
  };
  ASSERT_EQ(cache.trial_index, 3);
  SlamConfig other = f.slam;
  other.seed = 10;
  expect_replayed(other, f.p_W_start, f.setup);
  other = f.slam;
  other.drift_fraction_of_distance *= 2;
  expect_replayed(other, f.p_W_start, f.setup);
  other = f.slam;
  other.anchor_relock_correction = 1;
  expect_replayed(other, f.p_W_start, f.setup);
  expect_replayed(f.slam, f.p_W_start + Eigen::Vector3d(0.5, 0, 0), f.setup);
  TrialSetup slower = f.setup;
  slower.walk.speed_m_per_s *= 0.5;
  expect_replayed(f.slam, f.p_W_start, slower);
  double t = 0;
  EXPECT_THROW(SessionMapAtTrial(f.setup, f.slam, f.p_W_start, kMaxSessionTrials, &t), std::invalid_argument);
}

// A collaborator's headset as the display (TrialSetup::collaborator): its camera where the walk's
// is on arriving at the waypoint, stamped with the wearer's map error of the moment (here a 2 cm
// shift of the map, put into the sample by hand) and no anchor error.
TEST(Collaborator, TheLiveFrameCarriesTheWearersMapErrorOfTheMoment) {
  Fixture f;
  f.setup.collaborator.waypoint = "foot_end";
  SlamSample at;
  at.X_WH_true = HeadTrajectory(f.setup.walk).X_WH(30.0);
  at.X_WH_est = Translation({0.02, 0, 0}) * at.X_WH_true;
  const ReflectiveDisplayView view = CollaboratorView(f.setup, f.slam.X_HC, at, 5);
  const HeadTrajectory walk(f.setup.walk);
  const Eigen::Isometry3d X_WC = walk.X_WH(walk.ArrivalTime(walk.FindWaypoint("foot_end"))) * f.slam.X_HC;
  EXPECT_TRUE(view.X_WC_true.isApprox(X_WC, 1e-12));
  EXPECT_TRUE(view.X_WC_est.isApprox(Translation({0.02, 0, 0}) * X_WC, 1e-12));
  EXPECT_GT(view.D_m, 0.5);
  f.setup.collaborator.waypoint = "nowhere";
  EXPECT_THROW(CollaboratorView(f.setup, f.slam.X_HC, at, 5), std::invalid_argument);
}

// In an exact map with an exact anchor, the collaborator standing where the display captured shows
// what the captured frame showed: the person aligns to the same pose.
TEST(Collaborator, AtTheCapturePointWithAnExactMapAndAnchorItIsTheCapturedDisplay) {
  Fixture f;
  const TrialOutcome captured = f.Run({});
  f.setup.collaborator.waypoint = "foot_end";
  const TrialOutcome live = f.Run({});
  EXPECT_TRUE(live.alignment.X_WV.isApprox(captured.alignment.X_WV, 1e-9));
  EXPECT_EQ(live.alignment.nudges, captured.alignment.nudges);
  // The trial does use the collaborator's frame: an anchor 5 cm off moves what the person settles on.
  f.setup.collaborator.colocalization_translation_mm = 50;
  EXPECT_FALSE(f.Run({}).alignment.X_WV.isApprox(captured.alignment.X_WV, 1e-6));
}

// The anchor's error: per axis normal with the configured deviations, drawn per trial seed.
TEST(Collaborator, TheAnchorErrorHasTheConfiguredSpread) {
  Fixture f;
  f.setup.collaborator.waypoint = "foot_end";
  f.setup.collaborator.colocalization_translation_mm = 10;
  f.setup.collaborator.colocalization_rotation_deg = 1;
  SlamSample at;
  at.X_WH_true = at.X_WH_est = HeadTrajectory(f.setup.walk).X_WH(30.0);
  const int n = 2000;
  Eigen::Vector3d sum_t2 = Eigen::Vector3d::Zero();
  double sum_angle2 = 0;
  for (int seed = 0; seed < n; ++seed) {
    const ReflectiveDisplayView view = CollaboratorView(f.setup, f.slam.X_HC, at, seed);
    const Eigen::Isometry3d C = view.X_WC_est * view.X_WC_true.inverse();  // M = identity here
    sum_t2 += C.translation().cwiseAbs2();
    sum_angle2 += std::pow(Eigen::AngleAxisd(C.linear()).angle(), 2);
  }
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::sqrt(sum_t2[k] / n), 0.010, 0.0008) << k;  // 10 mm
  // The rotation vector is normal per axis: |w|^2 has mean 3 sigma^2.
  EXPECT_NEAR(std::sqrt(sum_angle2 / n), std::sqrt(3.0) * 1.0 * M_PI / 180, 0.0025);
}

TEST(AlignmentResult, PoseAtATime) {
  AlignmentResult r;
  r.poses = {{0.0, Translation({0, 0, 0})}, {7.5, Translation({1, 0, 0})}, {13.0, Translation({2, 0, 0})}};
  EXPECT_EQ(r.X_WV_at(0).translation().x(), 0);
  EXPECT_EQ(r.X_WV_at(7.4).translation().x(), 0);
  EXPECT_EQ(r.X_WV_at(7.5).translation().x(), 1);
  EXPECT_EQ(r.X_WV_at(100).translation().x(), 2);
}

}  // namespace
}  // namespace orbed::hmd
