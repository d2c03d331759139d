#include "hmd_emulator/user_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/random.h"
#include "base/units.h"
#include "base/yaml_fields.h"
#include "sim/distance_closed_form.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

constexpr double kArcminToRad = M_PI / (180.0 * 60.0);

Eigen::Matrix3d Skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d S;
  S << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return S;
}

// d(point)/d(ξ) for the nudge x' = c + exp(ω)(x − c) + v at ξ = 0: [−[x − c]×, I].
Eigen::Matrix<double, 3, 6> PointJacobian(const Eigen::Vector3d& x, const Eigen::Vector3d& c) {
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>() = -Skew(x - c);
  J.rightCols<3>() = Eigen::Matrix3d::Identity();
  return J;
}

Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& p) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& x : p) c += x;
  return p.empty() ? c : Eigen::Vector3d(c / static_cast<double>(p.size()));
}

// Pixel of p_W through the camera at X_WC with K, and du/dp_W (2×3). False behind the camera.
bool ProjectWithJacobian(const geometry::Intrinsics& in, const Eigen::Isometry3d& X_CW,
                         const Eigen::Vector3d& p_W, Eigen::Vector2d* uv, Eigen::Matrix<double, 2, 3>* J) {
  const Eigen::Vector3d y = X_CW * p_W;
  if (!(y.z() > 1e-6)) return false;
  const double iz = 1.0 / y.z();
  *uv = Eigen::Vector2d(in.fx_px * y.x() * iz + in.cx_px, in.fy_px * y.y() * iz + in.cy_px);
  Eigen::Matrix<double, 2, 3> du_dy;
  du_dy << in.fx_px * iz, 0, -in.fx_px * y.x() * iz * iz, 0, in.fy_px * iz, -in.fy_px * y.y() * iz * iz;
  *J = du_dy * X_CW.linear();
  return true;
}

bool InImage(const geometry::Intrinsics& in, const Eigen::Vector2d& uv) {
  return uv.x() >= 0 && uv.y() >= 0 && uv.x() <= in.width_px - 1 && uv.y() <= in.height_px - 1;
}

}  // namespace

Eigen::Isometry3d DefaultStartOffset() {
  Eigen::Isometry3d X_RV = Eigen::Isometry3d::Identity();
  X_RV.translation() = Eigen::Vector3d(0.10, -0.08, 0.05);
  X_RV.linear() = sim::RotationFromRpyDeg(Eigen::Vector3d(2.0, -1.5, 4.0));
  return X_RV;
}

UserConfig ParseUserConfig(const YAML::Node& node, const std::string& source, const std::string& key,
                           const UserConfig& base) {
  const YamlFields f(source);
  f.CheckKeys(node, key, {"seed", "start_offset", "direct_view", "perception", "belief", "nudging", "time"});
  UserConfig c = base;
  c.seed = static_cast<std::uint64_t>(
      f.IntegerOr(node, "seed", key, static_cast<long long>(c.seed), 0, (1LL << 62)));
  if (node["start_offset"]) {
    const std::string k = key + ".start_offset";
    const YAML::Node s = node["start_offset"];
    f.CheckKeys(s, k, {"position_m", "rpy_deg"});
    if (s["position_m"]) c.X_RV_start.translation() = f.Vector3(s["position_m"], k + ".position_m", "m");
    if (s["rpy_deg"])
      c.X_RV_start.linear() = sim::RotationFromRpyDeg(f.Vector3(s["rpy_deg"], k + ".rpy_deg", "deg"));
  }
  const double inf = INFINITY;
  {
    const std::string k = key + ".direct_view";
    const YAML::Node d = f.Section(node, "direct_view", k);
    f.CheckKeys(
        d, k,
        {"lateral_noise_arcmin", "lateral_bias_arcmin", "depth_bias_fraction_std",
         "depth_user_bias_fraction_std", "depth_noise_fraction_std", "user_scale_log_sigma", "size_blind"});
    c.size_blind = f.BoolOr(d, "size_blind", k, c.size_blind);
    c.lateral_noise_arcmin =
        f.NumberOr(d, "lateral_noise_arcmin", k, c.lateral_noise_arcmin, 0, 600, "arcmin");
    c.lateral_bias_arcmin = f.NumberOr(d, "lateral_bias_arcmin", k, c.lateral_bias_arcmin, 0, 600, "arcmin");
    c.depth_bias_fraction_std = f.NumberOr(d, "depth_bias_fraction_std", k, c.depth_bias_fraction_std, 0, 1);
    c.depth_user_bias_fraction_std =
        f.NumberOr(d, "depth_user_bias_fraction_std", k, c.depth_user_bias_fraction_std, 0, 1);
    c.depth_noise_fraction_std =
        f.NumberOr(d, "depth_noise_fraction_std", k, c.depth_noise_fraction_std, 0, 1);
    c.user_scale_log_sigma = f.NumberOr(d, "user_scale_log_sigma", k, c.user_scale_log_sigma, 0, 3);
  }
  {
    const std::string k = key + ".perception";
    const YAML::Node d = f.Section(node, "perception", k);
    f.CheckKeys(d, k, {"fov_h_deg", "fov_v_deg", "occlusion"});
    c.fov_h_deg = f.NumberOr(d, "fov_h_deg", k, c.fov_h_deg, 1, 179, "deg");
    c.fov_v_deg = f.NumberOr(d, "fov_v_deg", k, c.fov_v_deg, 1, 179, "deg");
    c.occlusion = f.BoolOr(d, "occlusion", k, c.occlusion);
  }
  {
    const std::string k = key + ".belief";
    const YAML::Node d = f.Section(node, "belief", k);
    f.CheckKeys(d, k, {"lateral_arcmin", "depth_fraction"});
    c.assumed_lateral_arcmin =
        f.NumberOr(d, "lateral_arcmin", k, c.assumed_lateral_arcmin, 1e-3, 600, "arcmin");
    c.assumed_depth_fraction = f.NumberOr(d, "depth_fraction", k, c.assumed_depth_fraction, 1e-5, 1);
  }
  {
    const std::string k = key + ".nudging";
    const YAML::Node d = f.Section(node, "nudging", k);
    f.CheckKeys(d, k,
                {"gain", "motor_noise_fraction", "motor_noise_translation_mm", "motor_noise_rotation_deg",
                 "max_nudges", "stop_lateral_arcmin", "stop_depth_fraction", "min_step_m", "min_step_deg",
                 "patience_nudges"});
    c.gain = f.NumberOr(d, "gain", k, c.gain, 0.01, 1.5);
    c.motor_noise_fraction = f.NumberOr(d, "motor_noise_fraction", k, c.motor_noise_fraction, 0, 1);
    c.motor_noise_translation_mm =
        f.NumberOr(d, "motor_noise_translation_mm", k, c.motor_noise_translation_mm, 0, 1000, "mm");
    c.motor_noise_rotation_deg =
        f.NumberOr(d, "motor_noise_rotation_deg", k, c.motor_noise_rotation_deg, 0, 90, "deg");
    c.max_nudges = static_cast<int>(f.IntegerOr(d, "max_nudges", k, c.max_nudges, 1, 10000));
    c.stop_lateral_arcmin = f.NumberOr(d, "stop_lateral_arcmin", k, c.stop_lateral_arcmin, 0, 600, "arcmin");
    c.stop_depth_fraction = f.NumberOr(d, "stop_depth_fraction", k, c.stop_depth_fraction, 0, 1);
    c.min_step_m = f.NumberOr(d, "min_step_m", k, c.min_step_m, 0, 1, "m");
    c.min_step_deg = f.NumberOr(d, "min_step_deg", k, c.min_step_deg, 0, 45, "deg");
    c.patience_nudges = static_cast<int>(f.IntegerOr(d, "patience_nudges", k, c.patience_nudges, 0, 10000));
  }
  {
    const std::string k = key + ".time";
    const YAML::Node d = f.Section(node, "time", k);
    f.CheckKeys(d, k, {"look_s", "display_look_s", "nudge_s"});
    c.look_time_s = f.NumberOr(d, "look_s", k, c.look_time_s, 0, inf, "s");
    c.display_look_time_s = f.NumberOr(d, "display_look_s", k, c.display_look_time_s, 0, inf, "s");
    c.nudge_time_s = f.NumberOr(d, "nudge_s", k, c.nudge_time_s, 0, inf, "s");
  }
  return c;
}

UserConfig LoadUserConfigFile(const std::string& path) {
  const YAML::Node root = YamlFields::LoadFile(path);
  const YamlFields f(path);
  f.CheckKeys(root, "", {"user"});
  return ParseUserConfig(f.Required(root, "user", "user"), path);
}

std::vector<Eigen::Vector3d> RobotModelPoints(const sim::RobotModel& model, const Eigen::VectorXd& q_rad) {
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q_rad);
  std::vector<Eigen::Vector3d> points;
  auto add = [&points](const Eigen::Vector3d& p) {
    for (const auto& x : points) {
      if ((x - p).norm() < 1e-3) return;  // one point per place (capsule caps repeat link origins)
    }
    points.push_back(p);
  };
  for (int i = 0; i < model.num_links(); ++i) {
    add(X_RL[i].translation());
    for (const auto& g : model.links()[i].collision) {
      const Eigen::Isometry3d X_RG = X_RL[i] * g.X_LG;
      add(X_RG.translation());
      if (g.kind == sim::CollisionPrimitive::Kind::kCylinder ||
          g.kind == sim::CollisionPrimitive::Kind::kCapsule) {
        const Eigen::Vector3d half = 0.5 * g.length_m * X_RG.linear().col(2);
        add(X_RG.translation() + half);
        add(X_RG.translation() - half);
      }
    }
  }
  return points;
}

std::vector<SightSolid> RobotSightSolids(const sim::RobotModel& model, const Eigen::VectorXd& q_rad) {
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q_rad);
  std::vector<SightSolid> solids;
  for (int i = 0; i < model.num_links(); ++i) {
    for (const auto& g : model.links()[i].collision) {
      const Eigen::Isometry3d X_RG = X_RL[i] * g.X_LG;
      SightSolid s;
      s.p_RA = s.p_RB = X_RG.translation();
      s.radius_m = g.radius_m;
      if (g.kind == sim::CollisionPrimitive::Kind::kCylinder ||
          g.kind == sim::CollisionPrimitive::Kind::kCapsule) {
        const Eigen::Vector3d half = 0.5 * g.length_m * X_RG.linear().col(2);
        s.p_RA -= half;
        s.p_RB += half;
      } else if (g.kind == sim::CollisionPrimitive::Kind::kBox) {
        Eigen::Index longest = 0;
        g.size_m.maxCoeff(&longest);
        Eigen::Vector3d sorted = g.size_m;
        std::sort(sorted.data(), sorted.data() + 3);
        s.radius_m = 0.5 * sorted[1];
        const double core = std::max(0.0, 0.5 * sorted[2] - s.radius_m);
        const Eigen::Vector3d half = core * X_RG.linear().col(longest);
        s.p_RA -= half;
        s.p_RB += half;
      }
      solids.push_back(s);
    }
  }
  return solids;
}

bool SeenPast(const std::vector<SightSolid>& solids_R, const Eigen::Vector3d& p_R_eye,
              const Eigen::Vector3d& p_R) {
  // A point this close to a solid's surface belongs to it (model points are link origins and axis
  // points, inside their own links) [m].
  constexpr double kContainsTolM = 1e-3;
  for (const SightSolid& solid : solids_R) {
    double s = 0, t = 0;
    const double own2 = sim::ClosestSegmentSegment(p_R, p_R, solid.p_RA, solid.p_RB, &s, &t);
    if (own2 <= std::pow(solid.radius_m + kContainsTolM, 2)) continue;
    const double sight2 = sim::ClosestSegmentSegment(p_R_eye, p_R, solid.p_RA, solid.p_RB, &s, &t);
    if (sight2 < solid.radius_m * solid.radius_m) return false;
  }
  return true;
}

double CaptureGazeDistance(const Eigen::Isometry3d& X_WC, const Eigen::Isometry3d& X_WR,
                           const std::vector<Eigen::Vector3d>& p_RQ) {
  const Eigen::Vector3d p_C = X_WC.inverse() * (X_WR * Centroid(p_RQ));
  return std::max(0.1, p_C.z());
}

PanelView SeePanel(const ReflectiveDisplayView& d, const Eigen::Isometry3d& A, const Eigen::Vector3d& p_W_eye,
                   double fov_h_deg, double fov_v_deg) {
  if (!std::isfinite(d.D_m) || !(d.D_m > 0))
    throw std::invalid_argument("reflective display: D must be finite and > 0, got " + std::to_string(d.D_m));
  const double s_m = 0.5 * d.D_m;
  const Eigen::Vector3d p_W_panel = A * (d.X_WC_est * Eigen::Vector3d(0, 0, s_m));
  PanelView v;
  v.distance_m = std::max(1e-3, (p_W_panel - p_W_eye).norm());
  v.px_per_rad = Eigen::Vector2d(d.intrinsics.fx_px, d.intrinsics.fy_px) * (v.distance_m / s_m);
  v.half_view_px = Eigen::Vector2d(std::tan(0.5 * fov_h_deg * kDegToRad) * v.px_per_rad.x(),
                                   std::tan(0.5 * fov_v_deg * kDegToRad) * v.px_per_rad.y());
  return v;
}

EmulatedUser::EmulatedUser(const UserConfig& config) : config_(config) {
  Random person(config.seed);
  depth_scale_ = person.LogNormalUnitMedian(config.user_scale_log_sigma);
  depth_user_bias_ = config.depth_user_bias_fraction_std * person.Normal();
}

// EmulatedUser::Align's steps (user_model.h, "The alignment"). Each draws from the trial's stream
// in the order the pinned runs were drawn in; one draw per statement (the arguments of one call are
// evaluated in an unspecified order: GCC last first, clang first first, so two draws in one call
// would make another person with another compiler).
namespace {

// The biases held through a trial: lateral α (x, y) and depth β in the direct view, one lateral
// bias per display panel [rad; β a fraction of ρ]. Draws: α_y, α_x, β, then per panel y, x.
struct TrialBiases {
  Eigen::Vector2d alpha_rad{Eigen::Vector2d::Zero()};
  double beta{0};
  std::vector<Eigen::Vector2d> display_bias_rad;  // the same acuity on each panel
};

TrialBiases DrawBiases(const UserConfig& c, double depth_scale, double depth_user_bias,
                       std::size_t num_displays, Random* rng) {
  TrialBiases b;
  const double alpha_y = c.lateral_bias_arcmin * kArcminToRad * rng->Normal();
  const double alpha_x = c.lateral_bias_arcmin * kArcminToRad * rng->Normal();
  b.alpha_rad = Eigen::Vector2d(alpha_x, alpha_y);
  b.beta = depth_scale * (depth_user_bias + c.depth_bias_fraction_std * rng->Normal());
  for (std::size_t j = 0; j < num_displays; ++j) {
    const double bias_y = c.lateral_bias_arcmin * kArcminToRad * rng->Normal();
    const double bias_x = c.lateral_bias_arcmin * kArcminToRad * rng->Normal();
    b.display_bias_rad.emplace_back(bias_x, bias_y);
  }
  return b;
}

// The scene as it is during the trial: real points r, the eye, the hologram's apparent-pose map A,
// what the robot does not hide of itself from the eye, and the see-through display's field of view
// about the head's line of sight (z of H).
struct TrueScene {
  Eigen::Isometry3d A;
  Eigen::Vector3d p_W_eye;
  std::vector<Eigen::Vector3d> r;
  Eigen::Vector3d p_RC;    // the model centroid, R
  Eigen::Vector3d real_c;  // the real centroid, W
  std::vector<bool> direct_unhidden;
  Eigen::Isometry3d X_HW;
  double tan_half_h{0}, tan_half_v{0};

  bool InView(const Eigen::Vector3d& p_H) const {
    return p_H.z() > 1e-6 && std::abs(p_H.x()) <= tan_half_h * p_H.z() &&
           std::abs(p_H.y()) <= tan_half_v * p_H.z();
  }
};

// What the robot does not hide of itself, seen from p_W_viewer.
std::vector<bool> UnhiddenFrom(const ViewingContext& ctx, const std::vector<Eigen::Vector3d>& p_RQ,
                               const UserConfig& c, const Eigen::Vector3d& p_W_viewer) {
  std::vector<bool> seen(p_RQ.size(), true);
  if (!c.occlusion) return seen;
  const Eigen::Vector3d p_R_viewer = ctx.X_WR.inverse() * p_W_viewer;
  for (std::size_t k = 0; k < p_RQ.size(); ++k) seen[k] = SeenPast(ctx.solids_R, p_R_viewer, p_RQ[k]);
  return seen;
}

TrueScene SeeTheScene(const ViewingContext& ctx, const std::vector<Eigen::Vector3d>& p_RQ,
                      const UserConfig& c) {
  TrueScene s;
  s.A = ctx.X_WH_true * ctx.X_WH_est.inverse();
  s.p_W_eye = ctx.X_WH_true.translation();
  s.r.resize(p_RQ.size());
  for (std::size_t k = 0; k < p_RQ.size(); ++k) s.r[k] = ctx.X_WR * p_RQ[k];
  s.p_RC = Centroid(p_RQ);
  s.real_c = ctx.X_WR * s.p_RC;
  s.direct_unhidden = UnhiddenFrom(ctx, p_RQ, c, s.p_W_eye);
  s.X_HW = ctx.X_WH_true.inverse();
  s.tan_half_h = std::tan(0.5 * c.fov_h_deg * kDegToRad);
  s.tan_half_v = std::tan(0.5 * c.fov_v_deg * kDegToRad);
  return s;
}

// A display's captured image of the real robot (true camera pose), and its overlay camera.
struct DisplayState {
  Eigen::Isometry3d X_CW_est;
  std::vector<bool> seen;
  std::vector<Eigen::Vector2d> u_real;
  Eigen::Vector2d u_centroid{Eigen::Vector2d::Zero()};  // the real centroid in the image
  Eigen::Vector2d px_per_rad{Eigen::Vector2d::Ones()};  // camera px per radian at the eye (u, v)
};

std::vector<DisplayState> CaptureDisplays(const ViewingContext& ctx, const std::vector<Eigen::Vector3d>& p_RQ,
                                          const UserConfig& c, const TrueScene& scene) {
  const std::size_t n = p_RQ.size();
  std::vector<DisplayState> displays;
  for (const auto& d : ctx.displays) {
    DisplayState s;
    s.X_CW_est = d.X_WC_est.inverse();
    const PanelView panel = SeePanel(d, scene.A, scene.p_W_eye, c.fov_h_deg, c.fov_v_deg);
    s.px_per_rad = panel.px_per_rad;
    const Eigen::Vector2d& half_view_px = panel.half_view_px;
    const Eigen::Vector2d image_centre(d.intrinsics.cx_px, d.intrinsics.cy_px);  // the panel's centre
    const std::vector<bool> unhidden = UnhiddenFrom(ctx, p_RQ, c, d.X_WC_true.translation());
    const geometry::CameraMatrix P_true = geometry::MakeCameraMatrix(d.intrinsics.K(), d.X_WC_true);
    s.seen.assign(n, false);
    s.u_real.assign(n, Eigen::Vector2d::Zero());
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int num_seen = 0;
    for (std::size_t k = 0; k < n; ++k) {
      Eigen::Vector2d uv;
      if (unhidden[k] && geometry::Project(P_true, scene.r[k], &uv) && InImage(d.intrinsics, uv) &&
          std::abs(uv.x() - image_centre.x()) <= half_view_px.x() &&
          std::abs(uv.y() - image_centre.y()) <= half_view_px.y()) {
        s.seen[k] = true;
        s.u_real[k] = uv;
        sum += uv;
        ++num_seen;
      }
    }
    // The centre of the image scale the person does not see: where the real centroid is imaged
    // (the mean of the points seen if it is behind the camera).
    if (!geometry::Project(P_true, scene.real_c, &s.u_centroid)) {
      s.u_centroid = num_seen > 0 ? Eigen::Vector2d(sum / num_seen) : sum;
    }
    displays.push_back(std::move(s));
  }
  return displays;
}

// One look: the normal equations of the person's fit (H, g) over the unknowns — the nudge ξ (0..5)
// about the pivot c_W and, when they are blind to small size differences, the apparent image scale
// σ of the hologram in the direct view (6) and in each display j (7 + j), nuisances they cannot
// act on — and what they perceive, per point, to judge it by.
struct Look {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  double depth2{0};
  // Direct view, per point: perceived lateral discrepancy and its size-nuisance direction, over ρ [rad].
  std::vector<Eigen::Vector2d> lateral_rad, size_dir_rad;
  // Displays, per point: the perceived 2D discrepancy [px], its size-nuisance direction, its display.
  std::vector<Eigen::Vector2d> display_px, display_size_dir;
  std::vector<int> display_of;
};

// The direct view's points (in view and unhidden): three draws per point (depth, b, a).
void LookDirectly(const std::vector<Eigen::Vector3d>& p_RQ, const UserConfig& c, double depth_scale,
                  const TrueScene& scene, const TrialBiases& biases, const Eigen::Isometry3d& X_WV,
                  const Eigen::Vector3d& c_W, double w_lat, double w_depth, Random* rng, Look* look) {
  const int num_unknowns = static_cast<int>(look->g.size());
  for (std::size_t k = 0; k < p_RQ.size(); ++k) {
    const Eigen::Vector3d x = X_WV * p_RQ[k];
    const Eigen::Vector3d h = scene.A * x;
    if (!scene.direct_unhidden[k] || !scene.InView(scene.X_HW * h)) continue;
    const Eigen::Vector3d ray = scene.r[k] - scene.p_W_eye;
    const double rho = ray.norm();
    if (!(rho > 1e-3)) continue;
    const Eigen::Vector3d nr = ray / rho;
    Eigen::Vector3d a = nr.cross(Eigen::Vector3d::UnitZ());
    a = a.norm() > 1e-6 ? Eigen::Vector3d(a.normalized()) : nr.unitOrthogonal();
    const Eigen::Vector3d b = nr.cross(a);
    const Eigen::Vector3d d = h - scene.r[k];
    const double noise_depth = depth_scale * c.depth_noise_fraction_std * rng->Normal();
    const double noise_b = c.lateral_noise_arcmin * kArcminToRad * rng->Normal();
    const double noise_a = c.lateral_noise_arcmin * kArcminToRad * rng->Normal();
    const Eigen::Vector3d perceived(a.dot(d) + rho * (biases.alpha_rad.x() + noise_a),
                                    b.dot(d) + rho * (biases.alpha_rad.y() + noise_b),
                                    nr.dot(d) + rho * (biases.beta + noise_depth));
    look->depth2 += perceived.z() * perceived.z() / (rho * rho);
    Eigen::Matrix3d B;
    B.row(0) = a.transpose();
    B.row(1) = b.transpose();
    B.row(2) = nr.transpose();
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3, num_unknowns);
    J.leftCols<6>() = B * scene.A.linear() * PointJacobian(x, c_W);
    if (c.size_blind) {
      // A uniform scale of what is seen about the centroid's line of sight moves each point
      // across its ray by σ · (r − c) (the perspective signature of a shift along that line).
      J(0, 6) = a.dot(scene.r[k] - scene.real_c);
      J(1, 6) = b.dot(scene.r[k] - scene.real_c);
    }
    look->lateral_rad.emplace_back(perceived.x() / rho, perceived.y() / rho);
    look->size_dir_rad.emplace_back(J(0, 6) / rho, J(1, 6) / rho);
    const Eigen::Vector3d w = Eigen::Vector3d(w_lat, w_lat, w_depth) / (rho * rho);
    look->H += J.transpose() * w.asDiagonal() * J;
    look->g += J.transpose() * w.asDiagonal() * perceived;
  }
}

// The displays' points (seen in the capture and projected by the overlay camera): two draws per
// point (y, x).
void LookAtDisplays(const ViewingContext& ctx, const std::vector<Eigen::Vector3d>& p_RQ, const UserConfig& c,
                    const std::vector<DisplayState>& displays, const TrialBiases& biases,
                    const Eigen::Isometry3d& X_WV, const Eigen::Vector3d& c_W, double w_lat, Random* rng,
                    Look* look) {
  const int num_unknowns = static_cast<int>(look->g.size());
  for (std::size_t j = 0; j < displays.size(); ++j) {
    const DisplayState& s = displays[j];
    for (std::size_t k = 0; k < p_RQ.size(); ++k) {
      if (!s.seen[k]) continue;
      const Eigen::Vector3d x = X_WV * p_RQ[k];
      Eigen::Vector2d u_virtual;
      Eigen::Matrix<double, 2, 3> du_dx;
      if (!ProjectWithJacobian(ctx.displays[j].intrinsics, s.X_CW_est, x, &u_virtual, &du_dx)) continue;
      const double noise_y = rng->Normal();
      const double noise_x = rng->Normal();
      const Eigen::Vector2d perceived =
          u_virtual - s.u_real[k] +
          s.px_per_rad.cwiseProduct(biases.display_bias_rad[j] + c.lateral_noise_arcmin * kArcminToRad *
                                                                     Eigen::Vector2d(noise_x, noise_y));
      Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2, num_unknowns);
      J.leftCols<6>() = du_dx * PointJacobian(x, c_W);
      // The display is a picture too: a hologram moved along the capture camera's line of sight
      // only changes its size in it, about the real centroid's image, and a size-blind person
      // does not see that either (the same nuisance as in the direct view, one per display).
      const Eigen::Vector2d size_dir =
          c.size_blind ? Eigen::Vector2d(s.u_real[k] - s.u_centroid) : Eigen::Vector2d::Zero();
      J.col(7 + static_cast<int>(j)) = size_dir;
      look->display_px.push_back(perceived);
      look->display_size_dir.push_back(size_dir);
      look->display_of.push_back(static_cast<int>(j));
      const Eigen::Vector2d w = w_lat * s.px_per_rad.cwiseInverse().cwiseAbs2();
      look->H += J.transpose() * w.asDiagonal() * J;
      look->g += J.transpose() * w.asDiagonal() * perceived;
    }
  }
}

// Decides the nudge: one Gauss–Newton step on the perceived discrepancies (tiny damping keeps an
// unobservable direction, if any, still). Returns the solution: ξ (0..5), then −σ per view.
Eigen::VectorXd DecideNudge(const UserConfig& c, Look* look) {
  Eigen::MatrixXd& H = look->H;
  const int num_unknowns = static_cast<int>(look->g.size());
  const double damping = 1e-12 * std::max(1.0, H.trace() / num_unknowns);
  if (!c.size_blind) {
    for (int i = 6; i < num_unknowns; ++i) H(i, i) = 1.0;  // every σ fixed at 0
  }
  for (int i = 6; i < num_unknowns; ++i) {
    if (!(H(i, i) > 0)) H(i, i) = 1.0;  // a view that shows no point: its σ is fixed at 0
  }
  return -(H + damping * Eigen::MatrixXd::Identity(num_unknowns, num_unknowns)).ldlt().solve(look->g);
}

// What the person judges: discrepancies net of the size differences they do not see (σ: the image
// scale that best explains what they see, per view); into result's perceived_* and *_points_seen.
void Judge(const Look& look, const Eigen::VectorXd& solution, const std::vector<DisplayState>& displays,
           AlignmentResult* result) {
  const double sigma = -solution[6];
  double lat2 = 0;
  for (std::size_t k = 0; k < look.lateral_rad.size(); ++k) {
    lat2 += (look.lateral_rad[k] - sigma * look.size_dir_rad[k]).squaredNorm();
  }
  double display2_rad = 0;  // as the eye sees it on the panels
  for (std::size_t k = 0; k < look.display_px.size(); ++k) {
    const int j = look.display_of[k];
    const double sigma_j = -solution[7 + j];
    display2_rad += (look.display_px[k] - sigma_j * look.display_size_dir[k])
                        .cwiseQuotient(displays[static_cast<std::size_t>(j)].px_per_rad)
                        .squaredNorm();
  }
  const int num_px = static_cast<int>(look.display_px.size());
  const double num_direct = std::max<double>(1.0, static_cast<double>(look.lateral_rad.size()));
  result->perceived_lateral_arcmin = std::sqrt(lat2 / num_direct) / kArcminToRad;
  result->perceived_depth_fraction = std::sqrt(look.depth2 / num_direct);
  result->perceived_display_arcmin = num_px > 0 ? std::sqrt(display2_rad / num_px) / kArcminToRad : 0.0;
  result->direct_points_seen = static_cast<int>(look.lateral_rad.size());
  result->display_points_seen = num_px;
}

// Whether the person stops after this look, and why ("" = they nudge): nothing in view, aligned,
// no better look in patience_nudges nudges (best_unsatisfied and nudges_since_better carry the
// person's patience from look to look), max_nudges, or a nudge too small to see.
std::string StopReason(const UserConfig& c, const AlignmentResult& result,
                       const Eigen::Matrix<double, 6, 1>& xi, double* best_unsatisfied,
                       int* nudges_since_better) {
  if (result.direct_points_seen == 0 && result.display_points_seen == 0) return "nothing_in_view";
  const bool satisfied =
      result.perceived_lateral_arcmin <= c.stop_lateral_arcmin &&
      result.perceived_depth_fraction <= c.stop_depth_fraction &&
      (result.display_points_seen == 0 || result.perceived_display_arcmin <= c.stop_lateral_arcmin);
  if (satisfied) return "aligned";
  // How far from satisfied the person sees it: the largest discrepancy over its threshold.
  const auto over = [](double value, double threshold) { return threshold > 0 ? value / threshold : 0.0; };
  const double unsatisfied = std::max({over(result.perceived_lateral_arcmin, c.stop_lateral_arcmin),
                                       over(result.perceived_depth_fraction, c.stop_depth_fraction),
                                       over(result.perceived_display_arcmin, c.stop_lateral_arcmin)});
  if (unsatisfied < *best_unsatisfied) {
    *best_unsatisfied = unsatisfied;
    *nudges_since_better = 0;
  } else if (c.patience_nudges > 0 && ++*nudges_since_better >= c.patience_nudges) {
    return "gave_up";
  }
  if (result.nudges >= c.max_nudges) return "max_nudges";
  const Eigen::Vector3d omega = xi.head<3>();
  const Eigen::Vector3d v = xi.tail<3>();
  if (v.norm() < c.min_step_m && omega.norm() < c.min_step_deg * kDegToRad) return "no_visible_improvement";
  return "";
}

// Carries the nudge out about the pivot c_W: a fraction (gain) of it, with motor noise on each
// component (6 draws, then 6 more with absolute motor noise). Returns the hologram's new pose.
Eigen::Isometry3d CarryOut(const UserConfig& c, const Eigen::Matrix<double, 6, 1>& xi,
                           const Eigen::Vector3d& c_W, const Eigen::Isometry3d& X_WV_before, Random* rng) {
  Eigen::Matrix<double, 6, 1> applied;
  for (int i = 0; i < 6; ++i) applied[i] = c.gain * xi[i] * (1.0 + c.motor_noise_fraction * rng->Normal());
  if (c.motor_noise_translation_mm > 0 || c.motor_noise_rotation_deg > 0) {
    for (int i = 0; i < 6; ++i) {
      const double sigma =
          i < 3 ? c.motor_noise_rotation_deg * kDegToRad : c.motor_noise_translation_mm * 1e-3;
      applied[i] += sigma * rng->Normal();
    }
  }
  const Eigen::Vector3d w_applied = applied.head<3>();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (w_applied.norm() > 0)
    T.linear() = Eigen::AngleAxisd(w_applied.norm(), w_applied.normalized()).toRotationMatrix();
  T.translation() = c_W + applied.tail<3>() - T.linear() * c_W;
  Eigen::Isometry3d X_WV = T * X_WV_before;
  X_WV.linear() = Eigen::Quaterniond(X_WV.linear()).normalized().toRotationMatrix();
  return X_WV;
}

}  // namespace

AlignmentResult EmulatedUser::Align(const ViewingContext& ctx, const std::vector<Eigen::Vector3d>& p_RQ,
                                    const Eigen::Isometry3d& X_WV_start, std::uint64_t trial_seed) const {
  if (p_RQ.empty()) throw std::invalid_argument("EmulatedUser::Align: no model points");
  const UserConfig& c = config_;
  Random rng(trial_seed);
  const TrialBiases biases = DrawBiases(c, depth_scale_, depth_user_bias_, ctx.displays.size(), &rng);
  const TrueScene scene = SeeTheScene(ctx, p_RQ, c);
  const std::vector<DisplayState> displays = CaptureDisplays(ctx, p_RQ, c, scene);
  const double w_lat =
      1.0 / std::pow(c.assumed_lateral_arcmin * kArcminToRad, 2);      // × 1/ρ² (× 1/px_per_rad²)
  const double w_depth = 1.0 / std::pow(c.assumed_depth_fraction, 2);  // × 1/ρ²
  const int num_unknowns = 7 + static_cast<int>(displays.size());

  AlignmentResult result;
  Eigen::Isometry3d X_WV = X_WV_start;
  result.poses.push_back({0.0, X_WV});
  double best_unsatisfied = INFINITY;  // patience: the best look so far
  int nudges_since_better = 0;
  while (true) {
    result.duration_s += c.look_time_s + c.display_look_time_s * static_cast<double>(displays.size());
    const Eigen::Vector3d c_W = X_WV * scene.p_RC;  // the nudge's pivot, map coordinates
    Look look;
    look.H = Eigen::MatrixXd::Zero(num_unknowns, num_unknowns);
    look.g = Eigen::VectorXd::Zero(num_unknowns);
    LookDirectly(p_RQ, c, depth_scale_, scene, biases, X_WV, c_W, w_lat, w_depth, &rng, &look);
    LookAtDisplays(ctx, p_RQ, c, displays, biases, X_WV, c_W, w_lat, &rng, &look);
    const Eigen::VectorXd solution = DecideNudge(c, &look);
    const Eigen::Matrix<double, 6, 1> xi = solution.head<6>();
    Judge(look, solution, displays, &result);
    result.stop_reason = StopReason(c, result, xi, &best_unsatisfied, &nudges_since_better);
    if (!result.stop_reason.empty()) break;
    X_WV = CarryOut(c, xi, c_W, X_WV, &rng);
    ++result.nudges;
    result.duration_s += c.nudge_time_s;
    result.poses.push_back({result.duration_s, X_WV});
  }
  result.X_WV = X_WV;
  return result;
}

Eigen::Isometry3d AlignmentResult::X_WV_at(double t_s) const {
  Eigen::Isometry3d X = poses.empty() ? X_WV : poses.front().X_WV;
  for (const TimedPose& p : poses) {
    if (p.t_s > t_s) break;
    X = p.X_WV;
  }
  return X;
}

bool EmulatedUser::SeesHologramMove(const Eigen::Isometry3d& X_WV_apparent_before,
                                    const Eigen::Isometry3d& X_WV_apparent_after,
                                    const std::vector<Eigen::Vector3d>& p_RQ,
                                    const Eigen::Vector3d& p_W_eye) const {
  if (p_RQ.empty()) return false;
  const PoseError moved = EvaluatePose(X_WV_apparent_after, X_WV_apparent_before, p_RQ, p_W_eye);
  const double rho_m = (X_WV_apparent_before * Centroid(p_RQ) - p_W_eye).norm();
  return moved.lateral_m > rho_m * config_.stop_lateral_arcmin * kArcminToRad ||
         moved.along_ray_m > rho_m * config_.stop_depth_fraction;
}

PoseError EvaluatePose(const Eigen::Isometry3d& X_WV_cmp, const Eigen::Isometry3d& X_WR,
                       const std::vector<Eigen::Vector3d>& p_RQ, const Eigen::Vector3d& p_W_eye) {
  PoseError e;
  if (p_RQ.empty()) return e;
  const Eigen::Vector3d p_RC = Centroid(p_RQ);
  const Eigen::Vector3d real_c = X_WR * p_RC;
  e.centroid_error_W_m = X_WV_cmp * p_RC - real_c;
  e.translation_error_m = e.centroid_error_W_m.norm();
  const Eigen::Vector3d ray = real_c - p_W_eye;
  const Eigen::Vector3d nr = ray.norm() > 0 ? Eigen::Vector3d(ray.normalized()) : Eigen::Vector3d::UnitZ();
  e.along_ray_m = std::abs(e.centroid_error_W_m.dot(nr));
  e.lateral_m = (e.centroid_error_W_m - e.centroid_error_W_m.dot(nr) * nr).norm();
  e.base_translation_error_m = (X_WV_cmp.translation() - X_WR.translation()).norm();
  e.rotation_error_deg = Eigen::AngleAxisd(X_WR.linear().transpose() * X_WV_cmp.linear()).angle() / kDegToRad;
  double sum = 0;
  for (const auto& p : p_RQ) sum += (X_WV_cmp * p - X_WR * p).norm();
  e.mean_point_error_m = sum / static_cast<double>(p_RQ.size());
  return e;
}

}  // namespace orbed::hmd
