#include "hmd_emulator/viraal_trial.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "base/hash.h"
#include "base/random.h"
#include "base/units.h"
#include "geometry/so3.h"

namespace orbed::hmd {
namespace {

// The alignment with setup.faults (viraal_trial.h's file comment). On entry out->alignment is the
// first attempt, made with `ctx` from out->at_alignment, the last sample `model` produced; on
// return out->alignment is the last attempt with duration_s the whole alignment's.
void AlignThroughFaults(const TrialSetup& setup, const EmulatedUser& user, std::uint64_t trial_seed,
                        ViewingContext ctx, SlamModel* model, TrialOutcome* out) {
  model->set_random_losses(false);
  const double dt = 1.0 / model->config().rate_hz;
  const double t0 = out->at_alignment.t_s;
  const Eigen::Isometry3d X_WH_stand = out->at_alignment.X_WH_true;
  // The hologram appears at A · X_WV (ApparentPose); A_attempt is A when the current attempt began.
  Eigen::Isometry3d A_attempt = ctx.X_WH_true * ctx.X_WH_est.inverse();
  long long k = 0;             // samples since the alignment sample
  double attempt_start_s = 0;  // when the current attempt began [s from t0]
  double paused_s = 0;         // waits inside the current attempt [s]
  TrackingFaultRecord& record = out->faults;
  for (const TimedFault& f : setup.faults) {
    const long long k_onset = std::max(k + 1, static_cast<long long>(std::ceil(f.at_s / dt - 1e-9)));
    const double onset_s = static_cast<double>(k_onset) * dt;
    if (onset_s >= attempt_start_s + paused_s + out->alignment.duration_s) break;  // submitted before
    while (k + 1 < k_onset) model->Step(X_WH_stand, t0 + static_cast<double>(++k) * dt);
    model->Force(f.fault);
    SlamSample s;
    do {
      s = model->Step(X_WH_stand, t0 + static_cast<double>(++k) * dt);
    } while (s.state != TrackingState::kRelocalized);
    const double wait_s = static_cast<double>(k - k_onset) * dt;
    ++record.losses;
    ++record.relocalizations;
    record.wait_s += wait_s;
    record.met.push_back({onset_s, f.fault});
    out->at_end = s;
    const Eigen::Isometry3d X_WV_now = out->alignment.X_WV_at(onset_s - attempt_start_s - paused_s);
    const Eigen::Isometry3d A_after = s.X_WH_true * s.X_WH_est.inverse();
    if (record.repeats < setup.max_repeats && user.SeesHologramMove(A_attempt * X_WV_now, A_after * X_WV_now,
                                                                    setup.p_RQ, s.X_WH_true.translation())) {
      ++record.repeats;
      ctx.X_WH_true = s.X_WH_true;
      ctx.X_WH_est = s.X_WH_est;
      out->alignment = user.Align(ctx, setup.p_RQ, X_WV_now, trial_seed);
      attempt_start_s = static_cast<double>(k) * dt;
      paused_s = 0;
      A_attempt = A_after;
    } else {
      paused_s += wait_s;  // carries on where they were
    }
  }
  out->alignment.duration_s += attempt_start_s + paused_s;
}

// The landmark annotation after the alignment (viraal_trial.h's file comment).
void AnnotateLandmarks(const TrialSetup& setup, std::uint64_t trial_seed, SlamModel* model,
                       TrialOutcome* out) {
  constexpr std::uint64_t kAnnotationSalt = 0x616e6e6f74617465ULL;  // "annotate"
  AnnotatingPerson person(model, out->at_end.t_s + 1.0 / model->config().rate_hz, setup.annotation,
                          SplitMix64(trial_seed ^ kAnnotationSalt));
  person.set_last(out->at_end);
  Eigen::Vector3d p_RL_mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : setup.p_RL) p_RL_mean += p;
  const Eigen::Vector3d look_at = setup.X_WR * (p_RL_mean / static_cast<double>(setup.p_RL.size()));
  const Eigen::Vector3d p_WH1 = out->at_end.X_WH_true.translation();
  // To the right of the line of sight (x of a head looking at look_at) is clockwise seen from above.
  const Eigen::AngleAxisd around(-setup.annotation_view_angle_deg * kDegToRad, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d p_WH2 = look_at + around * (p_WH1 - look_at);
  // Every landmark, real then hologram, from where the person stands.
  auto annotate_all = [&](const Eigen::Vector3d& p_WH) {
    for (std::size_t l = 0; l < setup.p_RL.size(); ++l) {
      out->annotation.push_back(
          {static_cast<int>(l), false, person.Annotate(p_WH, setup.X_WR * setup.p_RL[l])});
      out->annotation.push_back(
          {static_cast<int>(l), true, person.AnnotateHologram(p_WH, out->alignment.X_WV, setup.p_RL[l])});
    }
  };
  annotate_all(p_WH1);
  person.Walk(p_WH1, p_WH2, look_at);
  annotate_all(p_WH2);
}

}  // namespace

WalkSamples WalkToAlignment(const TrialSetup& setup, double t0_s, SlamModel* model) {
  const HeadTrajectory trajectory(setup.walk);
  auto waypoint = [&trajectory](const std::string& name) {
    const int i = trajectory.FindWaypoint(name);
    if (i < 0) throw std::invalid_argument("RunTrial: the walk has no waypoint '" + name + "'");
    return i;
  };
  const double t_align = trajectory.ArrivalTime(waypoint(setup.align_waypoint)) + setup.settle_s;
  std::vector<double> t_capture;
  for (const auto& name : setup.capture_waypoints)
    t_capture.push_back(trajectory.ArrivalTime(waypoint(name)));

  WalkSamples out;
  const double dt = 1.0 / model->config().rate_hz;
  std::vector<bool> captured(t_capture.size(), false);
  out.at_capture.resize(t_capture.size());
  const long long steps = static_cast<long long>(std::ceil(t_align / dt - 1e-9));
  for (long long k = 0; k <= steps; ++k) {
    const double t = std::min(k * dt, t_align);
    const SlamSample s = model->Step(trajectory.X_WH(t), t0_s + t);
    if (s.state == TrackingState::kRelocalized) ++out.relocalizations;
    for (std::size_t j = 0; j < t_capture.size(); ++j) {
      if (!captured[j] && t >= t_capture[j] - 1e-9 && s.state == TrackingState::kTracking) {
        out.at_capture[j] = s;
        captured[j] = true;
      }
    }
    out.at_alignment = s;
  }
  // A person waits for the headset to track again before aligning (holograms swim or freeze while
  // tracking is limited or lost): keep standing until TRACKING, for at most max_wait_s.
  const Eigen::Isometry3d X_WH_stand = trajectory.X_WH(t_align);
  for (double t = t_align + dt;
       out.at_alignment.state != TrackingState::kTracking && t <= t_align + setup.max_wait_s; t += dt) {
    out.at_alignment = model->Step(X_WH_stand, t0_s + t);
    if (out.at_alignment.state == TrackingState::kRelocalized) ++out.relocalizations;
  }
  // A display whose waypoint was passed while tracking never recovered takes the alignment's frame.
  for (std::size_t j = 0; j < t_capture.size(); ++j) {
    if (!captured[j]) out.at_capture[j] = out.at_alignment;
  }
  return out;
}

double WalkStraight(const Eigen::Vector3d& p_W_from, const Eigen::Vector3d& p_W_to,
                    const HeadTrajectoryConfig& walk, double t0_s, SlamModel* model) {
  if ((p_W_to - p_W_from).norm() < 1e-6) return t0_s;
  HeadTrajectoryConfig leg;
  leg.speed_m_per_s = walk.speed_m_per_s;
  leg.p_W_look_at = walk.p_W_look_at;
  leg.waypoints = {{"from", p_W_from, 0.0, {}}, {"to", p_W_to, 0.0, {}}};
  const HeadTrajectory trajectory(leg);
  const double dt = 1.0 / model->config().rate_hz;
  const double t_end = trajectory.ArrivalTime(1);
  const long long steps = static_cast<long long>(std::ceil(t_end / dt - 1e-9));
  for (long long k = 1; k <= steps; ++k) {
    const double t = std::min(static_cast<double>(k) * dt, t_end);
    model->Step(trajectory.X_WH(t), t0_s + t);
  }
  return t0_s + t_end;
}

std::string SessionMapKey(const TrialSetup& setup, const SlamConfig& slam, const Eigen::Vector3d& p_W_start) {
  std::ostringstream key;
  key << std::hexfloat;
  auto v3 = [&key](const Eigen::Vector3d& v) { key << v.x() << ',' << v.y() << ',' << v.z() << ';'; };
  key << slam.seed << ';' << slam.rate_hz << ';' << slam.jitter_translation_std_m << ';'
      << slam.jitter_rotation_std_deg << ';' << slam.drift_fraction_of_distance << ';'
      << slam.drift_yaw_deg_per_m << ';' << slam.drift_direction_correlation_m << ';' << slam.anchor_radius_m
      << ';' << slam.anchor_relock_correction << ';' << slam.tracking_loss_rate_per_min << ';'
      << slam.limited_mean_s << ';' << slam.limited_drift_multiplier << ';' << slam.lost_probability << ';'
      << slam.lost_mean_s << ';' << slam.relocalization_correction << ';' << slam.jump_translation_std_m
      << ';' << slam.jump_yaw_std_deg << ';';
  v3(p_W_start);
  key << setup.walk.speed_m_per_s << ';' << setup.walk.loop << ';';
  v3(setup.walk.p_W_look_at);
  for (const HeadWaypoint& w : setup.walk.waypoints) {
    key << w.name.size() << ':' << w.name << ';' << w.dwell_s << ';';
    v3(w.p_WH);
    if (w.p_W_look_at) v3(*w.p_W_look_at);
  }
  key << setup.align_waypoint.size() << ':' << setup.align_waypoint << ';' << setup.settle_s << ';'
      << setup.max_wait_s;
  return key.str();
}

SlamModel SessionMapAtTrial(const TrialSetup& setup, const SlamConfig& session_slam,
                            const Eigen::Vector3d& p_W_session_start, int trial_index, double* t_s,
                            SessionMapCache* cache) {
  if (trial_index < 0 || trial_index >= kMaxSessionTrials) {
    throw std::invalid_argument("SessionMapAtTrial: trial index " + std::to_string(trial_index) +
                                " outside 0.." + std::to_string(kMaxSessionTrials - 1));
  }
  if (setup.walk.waypoints.empty())
    throw std::invalid_argument("SessionMapAtTrial: the walk has no waypoints");
  const Eigen::Vector3d p_W_walk_start = setup.walk.waypoints.front().p_WH;
  const double dt = 1.0 / session_slam.rate_hz;
  const std::string key = cache ? SessionMapKey(setup, session_slam, p_W_session_start) : std::string();
  const bool cached = cache && cache->model && cache->key == key && cache->trial_index <= trial_index;
  std::optional<SlamModel> model;
  int k = 0;
  double t = 0;  // when the walk of trial k begins, minus dt
  if (cached) {
    model = cache->model;
    k = cache->trial_index;
    t = cache->t_arrived_s;
  } else {
    model.emplace(session_slam);
    // Where the person puts the headset on: the map's origin.
    HeadTrajectoryConfig here = setup.walk;
    here.waypoints = {{"start", p_W_session_start, 0.0, {}}};
    model->Step(HeadTrajectory(here).X_WH(0), 0.0);
    t = WalkStraight(p_W_session_start, p_W_walk_start, setup.walk, 0.0, &*model);
  }
  for (; k < trial_index; ++k) {
    const SlamSample aligned = WalkToAlignment(setup, t + dt, &*model).at_alignment;
    t = WalkStraight(aligned.X_WH_true.translation(), p_W_walk_start, setup.walk, aligned.t_s, &*model);
  }
  *t_s = t + dt;
  if (cache) {
    cache->model = model;
    cache->trial_index = trial_index;
    cache->t_arrived_s = t;
    cache->key = key;
  }
  return std::move(*model);
}

Eigen::Isometry3d AnchorError(const CollaboratorDisplay& collaborator, std::uint64_t seed) {
  constexpr std::uint64_t kCollaboratorSalt = 0x636f6c6c61626f72ULL;  // "collabor"
  Random random(SplitMix64(seed ^ kCollaboratorSalt));
  const Eigen::Vector3d t_m = 1e-3 * collaborator.colocalization_translation_mm * random.Normal3();
  const Eigen::Vector3d w_rad = kDegToRad * collaborator.colocalization_rotation_deg * random.Normal3();
  Eigen::Isometry3d C = Eigen::Isometry3d::Identity();
  C.linear() = geometry::ExpSO3(w_rad);
  C.translation() = t_m;
  return C;
}

ReflectiveDisplayView CollaboratorView(const TrialSetup& setup, const Eigen::Isometry3d& X_HC,
                                       const SlamSample& at, std::uint64_t trial_seed) {
  ReflectiveDisplayView view;
  view.intrinsics = setup.intrinsics;
  if (setup.collaborator.X_WC_true) {
    view.X_WC_true = *setup.collaborator.X_WC_true;
  } else {
    const HeadTrajectory walk(setup.walk);
    const int waypoint = walk.FindWaypoint(setup.collaborator.waypoint);
    if (waypoint < 0) {
      throw std::invalid_argument("collaborator: the walk has no waypoint '" + setup.collaborator.waypoint +
                                  "'");
    }
    view.X_WC_true = walk.X_WH(walk.ArrivalTime(waypoint)) * X_HC;
  }
  const Eigen::Isometry3d C = AnchorError(setup.collaborator, trial_seed);
  const Eigen::Isometry3d M = at.X_WH_est * at.X_WH_true.inverse();
  view.X_WC_est = C * M * view.X_WC_true;
  view.D_m = CaptureGazeDistance(view.X_WC_true, setup.X_WR, setup.p_RQ);
  return view;
}

ViewingContext TrialViewingContext(const TrialSetup& setup, const SlamSample& at,
                                   const std::vector<SlamSample>& at_capture) {
  ViewingContext ctx;
  ctx.X_WR = setup.X_WR;
  ctx.X_WH_true = at.X_WH_true;
  ctx.X_WH_est = at.X_WH_est;
  ctx.solids_R = setup.solids_R;
  for (const auto& cap : at_capture) {
    ReflectiveDisplayView view;
    view.intrinsics = setup.intrinsics;
    view.X_WC_true = cap.X_WC_true;
    view.X_WC_est = cap.X_WC_est;
    view.D_m = CaptureGazeDistance(cap.X_WC_true, setup.X_WR, setup.p_RQ);
    ctx.displays.push_back(view);
  }
  return ctx;
}

TrialOutcome RunTrial(const TrialSetup& setup, const SlamConfig& slam, const EmulatedUser& user,
                      const Eigen::Isometry3d& X_WV_start, std::uint64_t trial_seed) {
  return RunTrialFrom(setup, SlamModel(slam), 0.0, user, X_WV_start, trial_seed);
}

TrialOutcome RunTrialFrom(const TrialSetup& setup, SlamModel model, double t0_s, const EmulatedUser& user,
                          const Eigen::Isometry3d& X_WV_start, std::uint64_t trial_seed) {
  TrialOutcome out;
  WalkSamples walked = WalkToAlignment(setup, t0_s, &model);
  out.at_alignment = walked.at_alignment;
  out.at_capture = std::move(walked.at_capture);
  out.relocalizations = walked.relocalizations;

  ViewingContext ctx = TrialViewingContext(setup, out.at_alignment, out.at_capture);
  if (setup.collaborator.active() && !ctx.displays.empty())
    ctx.displays[0] = CollaboratorView(setup, model.config().X_HC, out.at_alignment, trial_seed);
  out.alignment = user.Align(ctx, setup.p_RQ, X_WV_start, trial_seed);
  out.at_end = out.at_alignment;
  if (!setup.faults.empty()) AlignThroughFaults(setup, user, trial_seed, ctx, &model, &out);
  const Eigen::Vector3d p_W_eye = out.at_end.X_WH_true.translation();
  out.registration = EvaluatePose(out.alignment.X_WV, setup.X_WR, setup.p_RQ, p_W_eye);
  out.augmentation = EvaluatePose(ApparentPose(out.at_end.X_WH_true, out.at_end.X_WH_est, out.alignment.X_WV),
                                  setup.X_WR, setup.p_RQ, p_W_eye);
  if (!setup.p_RL.empty()) AnnotateLandmarks(setup, trial_seed, &model, &out);
  return out;
}

}  // namespace orbed::hmd
