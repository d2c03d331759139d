// Gaze ray casting against closed-form intersections: box faces, cylinder side and caps, sphere,
// capsule body and caps, rays from inside, misses, range limits; on the OR scene the hit body's
// name, the real/virtual filter, and agreement with the renderer's depth image.
#include "hmd_emulator/gaze.h"

#include <cmath>
#include <cstdlib>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "render/renderer.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

Eigen::Isometry3d Pose(const Eigen::Vector3d& rpy_deg, const Eigen::Vector3d& p) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = sim::RotationFromRpyDeg(rpy_deg);
  X.translation() = p;
  return X;
}

render::Primitive Make(render::Primitive::Shape shape, const Eigen::Isometry3d& X_WG, double r = 0,
                       double l = 0, const Eigen::Vector3d& size = Eigen::Vector3d::Zero()) {
  render::Primitive p;
  p.shape = shape;
  p.X_WG = X_WG;
  p.radius_m = r;
  p.length_m = l;
  p.size_m = size;
  return p;
}

using Shape = render::Primitive::Shape;

TEST(Gaze, BoxFacesByHand) {
  const Eigen::Isometry3d X_WG = Pose({0, 0, 0}, {1, 2, 3});
  const render::Primitive box = Make(Shape::kBox, X_WG, 0, 0, {0.4, 0.6, 0.8});
  // Along +x from 2 m away: hits the -x face at x = 0.8, distance 2 - 0.2.
  RayHit h = IntersectPrimitive(box, {-1, 2.1, 3.1}, {1, 0, 0});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 1.8, 1e-12);
  EXPECT_LT((h.p_WQ - Eigen::Vector3d(0.8, 2.1, 3.1)).norm(), 1e-12);
  EXPECT_LT((h.normal_W - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-12);
  // Down onto the top face.
  h = IntersectPrimitive(box, {1.1, 2.2, 5}, {0, 0, -1});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 5 - 3.4, 1e-12);
  EXPECT_LT((h.normal_W - Eigen::Vector3d(0, 0, 1)).norm(), 1e-12);
  // Oblique through an edge region: direction (1, 1, 0)/√2 from (0.3, 1.2, 3): the -x slab is entered
  // at t = 0.5√2 (x = 0.8, y = 1.7), the -y slab at t = 0.5√2 (y = 1.7) too: the corner edge.
  h = IntersectPrimitive(box, {0.3, 1.2, 3}, Eigen::Vector3d(1, 1, 0).normalized());
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 0.5 * std::sqrt(2.0), 1e-12);
  // Passing beside: miss; pointing away: miss; beyond range: miss.
  EXPECT_FALSE(IntersectPrimitive(box, {-1, 2.31, 3}, {1, 0, 0}).hit);
  EXPECT_FALSE(IntersectPrimitive(box, {-1, 2, 3}, {-1, 0, 0}).hit);
  EXPECT_FALSE(IntersectPrimitive(box, {-1, 2, 3}, {1, 0, 0}, 1.7).hit);
  // From inside: the exit face.
  h = IntersectPrimitive(box, {1, 2, 3}, {0, 1, 0});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 0.3, 1e-12);
  EXPECT_LT((h.normal_W - Eigen::Vector3d(0, 1, 0)).norm(), 1e-12);
}

TEST(Gaze, RotatedBoxHitsLieOnTheSurfaceAndAreFirst) {
  const Eigen::Isometry3d X_WG = Pose({20, -35, 50}, {0.2, -0.1, 1.0});
  const Eigen::Vector3d half(0.3, 0.2, 0.1);
  const render::Primitive box = Make(Shape::kBox, X_WG, 0, 0, 2 * half);
  const Eigen::Isometry3d X_GW = X_WG.inverse();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  int hits = 0;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d o = X_WG * Eigen::Vector3d(2 * U(rng), 2 * U(rng), 2 + U(rng));
    const Eigen::Vector3d target = X_WG * Eigen::Vector3d(0.4 * U(rng), 0.3 * U(rng), 0.15 * U(rng));
    const Eigen::Vector3d d = (target - o).normalized();
    const RayHit h = IntersectPrimitive(box, o, d);
    // Oracle: sample the ray; the first sample inside the box brackets the true entry.
    double t_in = -1;
    for (double t = 0; t < 5; t += 1e-4) {
      const Eigen::Vector3d p_G = X_GW * (o + t * d);
      if ((p_G.cwiseAbs() - half).maxCoeff() <= 0) {
        t_in = t;
        break;
      }
    }
    ASSERT_EQ(h.hit, t_in >= 0) << i;
    if (!h.hit) continue;
    ++hits;
    EXPECT_NEAR(h.distance_m, t_in, 1.1e-4);
    const Eigen::Vector3d q_G = X_GW * h.p_WQ;
    EXPECT_NEAR((q_G.cwiseAbs() - half).maxCoeff(), 0, 1e-9);
  }
  EXPECT_GT(hits, 200);
}

TEST(Gaze, SphereByHand) {
  const render::Primitive s = Make(Shape::kSphere, Pose({0, 0, 0}, {0, 0, 1}), 0.5);
  RayHit h = IntersectPrimitive(s, {0, -3, 1}, {0, 1, 0});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 2.5, 1e-12);
  // Off-centre by 0.3: chord half-length 0.4, so the hit is at y = -0.4.
  h = IntersectPrimitive(s, {0.3, -3, 1}, {0, 1, 0});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 2.6, 1e-12);
  EXPECT_LT((h.normal_W - Eigen::Vector3d(0.6, -0.8, 0)).norm(), 1e-12);
  EXPECT_FALSE(IntersectPrimitive(s, {0.51, -3, 1}, {0, 1, 0}).hit);
  // From the centre: the radius.
  h = IntersectPrimitive(s, {0, 0, 1}, Eigen::Vector3d(1, 2, 3).normalized());
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 0.5, 1e-12);
}

TEST(Gaze, CylinderSideAndCapsByHand) {
  // Pitch 90 deg: the axis z_G lies along W's x; the checks below use z_G from the pose itself.
  const Eigen::Isometry3d X_WG = Pose({0, 90, 0}, {1, 0, 1});
  const Eigen::Vector3d axis_W = X_WG.linear().col(2);
  const render::Primitive c = Make(Shape::kCylinder, X_WG, 0.2, 1.0);
  // Perpendicular to the axis at its middle, from 2 m: hits the side at 2 - 0.2.
  const Eigen::Vector3d perp = axis_W.unitOrthogonal();
  RayHit h = IntersectPrimitive(c, X_WG.translation() + 2 * perp, -perp);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 1.8, 1e-12);
  EXPECT_LT((h.normal_W - perp).norm(), 1e-12);
  // Along the axis from 3 m: the end cap at 3 - 0.5.
  h = IntersectPrimitive(c, X_WG.translation() - 3 * axis_W + 0.1 * perp, axis_W);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 2.5, 1e-12);
  EXPECT_LT((h.normal_W + axis_W).norm(), 1e-12);
  // Perpendicular but past the end: miss.
  EXPECT_FALSE(IntersectPrimitive(c, X_WG.translation() + 0.55 * axis_W + 2 * perp, -perp).hit);
  // Oblique past the cap's rim: from (0, 0, 0.9) in G along (1, 0, -1)/√2 the radius 0.2 is reached
  // at t = 0.2 √2 where z = 0.7 (beyond the end, not the side) and the cap plane z = 0.5 at
  // t = 0.4 √2 where the radius is 0.4 > 0.2 (outside the cap): a miss.
  const Eigen::Vector3d o_G(0, 0, 0.9), d_G = Eigen::Vector3d(1, 0, -1).normalized();
  EXPECT_FALSE(IntersectPrimitive(c, X_WG * o_G, X_WG.linear() * d_G).hit);
  // Oblique entering the side: from (0.5, 0, 0) toward (-1, 0, -1)/√2: radial 0.2 at t = 0.3 √2
  // (z = -0.3, inside the length): side hit.
  h = IntersectPrimitive(c, X_WG * Eigen::Vector3d(0.5, 0, 0),
                         X_WG.linear() * Eigen::Vector3d(-1, 0, -1).normalized());
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 0.3 * std::sqrt(2.0), 1e-12);
}

TEST(Gaze, CapsuleBodyAndCapsByHand) {
  const Eigen::Isometry3d X_WG = Pose({30, 0, 10}, {0, 0, 1});
  const Eigen::Vector3d z = X_WG.linear().col(2);
  const Eigen::Vector3d x = X_WG.linear().col(0);
  const render::Primitive c = Make(Shape::kCapsule, X_WG, 0.1, 0.6);  // caps at ±0.3
  // Along the axis from 2 m: the cap's pole at 2 - 0.3 - 0.1.
  RayHit h = IntersectPrimitive(c, X_WG.translation() + 2 * z, -z);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 1.6, 1e-12);
  // Perpendicular at the middle: side at 1 - 0.1.
  h = IntersectPrimitive(c, X_WG.translation() + 1 * x, -x);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 0.9, 1e-12);
  // Perpendicular at z_G = 0.36 (cap region): sphere chord, 1 - sqrt(0.1^2 - 0.06^2) = 1 - 0.08.
  h = IntersectPrimitive(c, X_WG.translation() + 0.36 * z + 1 * x, -x);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 0.92, 1e-12);
  // Perpendicular at z_G = 0.41: beyond the cap, miss.
  EXPECT_FALSE(IntersectPrimitive(c, X_WG.translation() + 0.41 * z + 1 * x, -x).hit);
  // From inside (the centre) along the axis: leaves through the cap pole at 0.4.
  h = IntersectPrimitive(c, X_WG.translation(), z);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 0.4, 1e-12);
}

TEST(Gaze, OperatingRoomNamesTheBodyAndSkipsTheHologram) {
  const sim::RobotModel robot =
      sim::RobotModel::LoadFile(orbed::SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
  const sim::Scene scene = sim::LoadSceneFile(orbed::SourceTreePath(sim::kDefaultSceneRelativePath));
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(7);  // arm straight up
  const Eigen::Isometry3d X_WV = scene.X_WR;           // hologram exactly on the real robot
  render::SceneGeometry g = render::SceneGeometry::MakeOperatingRoom(scene, robot, q, scene.X_WR, &X_WV);
  // Straight down onto the patient's legs (top at 0.88 + 0.08).
  RayHit h = CastRay(g, {0.9, 0.0, 2.0}, {0, 0, -1});
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.body_name, "patient_legs");
  EXPECT_NEAR(h.distance_m, 2.0 - 0.96, 1e-12);
  // Upward: nothing (no ceiling).
  h = CastRay(g, {0.9, 0.0, 2.0}, {0, 0, 1});
  EXPECT_FALSE(h.hit);
  EXPECT_EQ(h.body_name, "");
  EXPECT_EQ(h.body, -1);
  // Horizontally at the robot's link 3 (the base at (0.25, -0.55, 0.75); link 3 spans 0.55..0.75 m
  // above it, radius 0.07): from 2 m in -x, the side of link 3's cylinder at 2 - 0.07.
  const Eigen::Vector3d o(0.25 - 2.0, -0.55, 0.75 + 0.65);
  h = CastRay(g, o, {1, 0, 0});
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.body_name, "iiwa_link_3");
  EXPECT_NEAR(h.distance_m, 2.0 - 0.07, 1e-9);
  h = CastRay(g, o, {1, 0, 0}, render::kVirtualOnly);
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.body_name, "virtual/iiwa_link_3");
  EXPECT_THROW(CastRay(g, o, {0, 0, 0}), std::invalid_argument);
}

TEST(Gaze, AgreesWithTheRendererOnAFlatFace) {
  const sim::RobotModel robot =
      sim::RobotModel::LoadFile(orbed::SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
  const sim::Scene scene = sim::LoadSceneFile(orbed::SourceTreePath(sim::kDefaultSceneRelativePath));
  render::SceneGeometry g =
      render::SceneGeometry::MakeOperatingRoom(scene, robot, Eigen::VectorXd::Zero(7), scene.X_WR);
  render::Mesh mesh;
  render::Tessellate(g, render::kRealWorld, {}, &mesh);
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  render::Renderer renderer(K);
  // Looking down at 60 deg onto the patient's torso from the bedside.
  Eigen::Isometry3d X_WC = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d eye(0.0, -1.2, 1.9), target(0.0, 0.0, 1.02);
  const Eigen::Vector3d zc = (target - eye).normalized();
  const Eigen::Vector3d xc = zc.cross(Eigen::Vector3d::UnitZ()).normalized();
  X_WC.linear() << xc, zc.cross(xc), zc;
  X_WC.translation() = eye;
  cv::Mat bgr, depth, ids;
  renderer.Render(mesh, X_WC, &bgr, &depth, &ids);
  for (const Eigen::Vector2i& uv :
       {Eigen::Vector2i(597, 322), Eigen::Vector2i(700, 400), Eigen::Vector2i(500, 250)}) {
    const Eigen::Vector3d ray_C((uv.x() - K.cx_px) / K.fx_px, (uv.y() - K.cy_px) / K.fy_px, 1.0);
    const RayHit h = CastRay(g, eye, X_WC.linear() * ray_C.normalized());
    ASSERT_TRUE(h.hit);
    EXPECT_EQ(g.bodies()[ids.at<int>(uv.y(), uv.x())].name, h.body_name);
    // depth is z_C; the ray's distance is along the (unnormalised) ray: z = t / |ray_C|.
    EXPECT_NEAR(depth.at<float>(uv.y(), uv.x()), h.distance_m / ray_C.norm(), 1e-4);
  }
}

}  // namespace
}  // namespace orbed::hmd
