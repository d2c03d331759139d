// Renderer oracles: analytic silhouette areas (convex hull of hand-projected box corners), depth of
// a fronto-parallel face, z-order of overlapping bodies, the principal point, near-plane clipping
// of a floor, the hologram overlay and JPEG coding; plus the OR scene renders with every link shown.
#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "render/scene_geometry.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::render {
namespace {

Primitive Box(const Eigen::Vector3d& size, const Eigen::Isometry3d& X_WG) {
  Primitive p;
  p.shape = Primitive::Shape::kBox;
  p.size_m = size;
  p.X_WG = X_WG;
  return p;
}

// Independent pinhole projection (no camera_model.h): K (R_CW p + p_CW).
Eigen::Vector2d HandProject(const geometry::Intrinsics& K, const Eigen::Isometry3d& X_WC,
                            const Eigen::Vector3d& p_W) {
  const Eigen::Matrix3d R_CW = X_WC.linear().transpose();
  const Eigen::Vector3d p_C = R_CW * (p_W - X_WC.translation());
  return {K.fx_px * p_C.x() / p_C.z() + K.cx_px, K.fy_px * p_C.y() / p_C.z() + K.cy_px};
}

double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Area of the convex hull (Andrew's monotone chain + shoelace).
double ConvexHullArea(std::vector<Eigen::Vector2d> pts) {
  std::sort(pts.begin(), pts.end(),
            [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  std::vector<Eigen::Vector2d> hull(2 * pts.size());
  size_t k = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && Cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
  double area = 0;
  for (size_t i = 0; i < hull.size(); ++i) {
    const auto& a = hull[i];
    const auto& b = hull[(i + 1) % hull.size()];
    area += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * std::abs(area);
}

int CountId(const cv::Mat& ids, int id) { return cv::countNonZero(ids == id); }

TEST(Renderer, BoxSilhouetteAreaMatchesAnalyticProjection) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  Renderer renderer(K);
  struct Case {
    Eigen::Vector3d size;
    Eigen::Vector3d centre;
    Eigen::Vector3d rpy_deg;
    Eigen::Vector3d eye;
  };
  const Case cases[] = {
      {{0.4, 0.3, 0.2}, {0.0, 0.0, 1.0}, {10, 20, 30}, {1.5, -1.2, 1.6}},
      {{0.8, 0.1, 0.5}, {0.3, 0.1, 0.9}, {-35, 5, 60}, {-1.0, -2.0, 1.8}},
      {{0.25, 0.25, 0.25}, {0.0, 0.0, 1.2}, {0, 0, 0}, {0.0, -2.5, 1.2}},  // one face head-on
  };
  for (const Case& c : cases) {
    Eigen::Isometry3d X_WG = Eigen::Isometry3d::Identity();
    X_WG.linear() = sim::RotationFromRpyDeg(c.rpy_deg);
    X_WG.translation() = c.centre;
    SceneGeometry g;
    const int body = g.AddBody("box", BodyKind::kSceneObject, ColorBgr{50, 100, 200}, Box(c.size, X_WG));
    Mesh mesh;
    Tessellate(g, kAllKinds, {}, &mesh);
    const Eigen::Isometry3d X_WC = geometry::LookAt(c.eye, c.centre + Eigen::Vector3d(0.05, -0.03, 0.02));
    cv::Mat bgr, ids;
    renderer.Render(mesh, X_WC, &bgr, nullptr, &ids);
    std::vector<Eigen::Vector2d> corners;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d p_G(((i & 1) ? 0.5 : -0.5) * c.size.x(), ((i & 2) ? 0.5 : -0.5) * c.size.y(),
                                ((i & 4) ? 0.5 : -0.5) * c.size.z());
      corners.push_back(HandProject(K, X_WC, X_WG * p_G));
    }
    for (const auto& uv : corners) {  // the oracle needs the whole box inside the image
      ASSERT_GT(uv.x(), 0);
      ASSERT_LT(uv.x(), K.width_px - 1);
      ASSERT_GT(uv.y(), 0);
      ASSERT_LT(uv.y(), K.height_px - 1);
    }
    const double expected = ConvexHullArea(corners);
    const double rendered = CountId(ids, body);
    EXPECT_GT(expected, 5000);
    EXPECT_NEAR(rendered / expected, 1.0, 0.02) << "expected " << expected << " px, got " << rendered;
  }
}

TEST(Renderer, DepthOfAFrontoParallelFaceIsItsDistance) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  Renderer renderer(K);
  SceneGeometry g;
  Eigen::Isometry3d X_WG = Eigen::Isometry3d::Identity();
  X_WG.translation() = Eigen::Vector3d(0, 0, 1.0);
  g.AddBody("box", BodyKind::kSceneObject, ColorBgr{}, Box(Eigen::Vector3d(0.5, 0.5, 0.5), X_WG));
  Mesh mesh;
  Tessellate(g, kAllKinds, {}, &mesh);
  // Camera 2 m in front of the -y face, looking along +y: the face is at depth 2 - 0.25 = 1.75 m.
  const Eigen::Isometry3d X_WC = geometry::LookAt({0, -2.0, 1.0}, {0, 0, 1.0});
  cv::Mat bgr, depth;
  renderer.Render(mesh, X_WC, &bgr, &depth);
  EXPECT_NEAR(depth.at<float>(322, 597), 1.75, 1e-4);
  EXPECT_NEAR(depth.at<float>(322 + 150, 597 - 200), 1.75, 1e-4);
  EXPECT_EQ(depth.at<float>(5, 5), 0.0f);  // nothing there
}

// Geometry beyond single precision (a box 1e300 m off, as a hostile pose on the bus could place it)
// tessellates to infinities: those triangles are skipped and the rest of the mesh is drawn as
// without them (found by fuzz_fixed_display: NaN shading cast to a colour byte).
TEST(Renderer, TrianglesBeyondFloatRangeAreSkipped) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  Renderer renderer(K);
  SceneGeometry near_only, with_far;
  Eigen::Isometry3d X_WG = Eigen::Isometry3d::Identity();
  X_WG.translation() = Eigen::Vector3d(0, 0, 1.0);
  near_only.AddBody("box", BodyKind::kSceneObject, ColorBgr{}, Box(Eigen::Vector3d(0.5, 0.5, 0.5), X_WG));
  with_far.AddBody("box", BodyKind::kSceneObject, ColorBgr{}, Box(Eigen::Vector3d(0.5, 0.5, 0.5), X_WG));
  Eigen::Isometry3d X_WF = Eigen::Isometry3d::Identity();
  X_WF.translation() = Eigen::Vector3d(0, 1e300, 1.0);
  with_far.AddBody("far", BodyKind::kSceneObject, ColorBgr{},
                   Box(Eigen::Vector3d(1e300, 1e300, 1e300), X_WF));
  // Finite in single precision, but their centroid's sum overflows: skipped too.
  Eigen::Isometry3d X_WN = Eigen::Isometry3d::Identity();
  X_WN.translation() = Eigen::Vector3d(0, 2e38, 1.0);
  with_far.AddBody("near_max", BodyKind::kSceneObject, ColorBgr{}, Box(Eigen::Vector3d(1, 1, 1), X_WN));
  Mesh a, b;
  Tessellate(near_only, kAllKinds, {}, &a);
  Tessellate(with_far, kAllKinds, {}, &b);
  const Eigen::Isometry3d X_WC = geometry::LookAt({0, -2.0, 1.0}, {0, 0, 1.0});
  cv::Mat bgr_a, bgr_b;
  renderer.Render(a, X_WC, &bgr_a);
  const int drawn_a = renderer.last_triangle_count();
  renderer.Render(b, X_WC, &bgr_b);
  EXPECT_EQ(renderer.last_triangle_count(), drawn_a);
  EXPECT_EQ(cv::norm(bgr_a, bgr_b, cv::NORM_INF), 0.0);
}

TEST(Renderer, NearerObjectWinsWhereTwoOverlapInEitherOrder) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  Renderer renderer(K);
  const Eigen::Isometry3d X_WC = geometry::LookAt({0, -3.0, 1.0}, {0, 0, 1.0});
  for (bool near_first : {true, false}) {
    SceneGeometry g;
    Eigen::Isometry3d X_near = Eigen::Isometry3d::Identity(), X_far = Eigen::Isometry3d::Identity();
    X_near.translation() = Eigen::Vector3d(0.1, -1.0, 1.0);  // 2 m from the camera
    X_far.translation() = Eigen::Vector3d(-0.1, 0.5, 1.05);  // 3.5 m, overlapping in the image
    const Primitive near_box = Box({0.3, 0.3, 0.3}, X_near);
    Primitive far_sphere;
    far_sphere.shape = Primitive::Shape::kSphere;
    far_sphere.radius_m = 0.4;
    far_sphere.X_WG = X_far;
    int near_id, far_id;
    if (near_first) {
      near_id = g.AddBody("near", BodyKind::kSceneObject, ColorBgr{0, 0, 255}, near_box);
      far_id = g.AddBody("far", BodyKind::kSceneObject, ColorBgr{255, 0, 0}, far_sphere);
    } else {
      far_id = g.AddBody("far", BodyKind::kSceneObject, ColorBgr{255, 0, 0}, far_sphere);
      near_id = g.AddBody("near", BodyKind::kSceneObject, ColorBgr{0, 0, 255}, near_box);
    }
    Mesh mesh;
    Tessellate(g, kAllKinds, {}, &mesh);
    cv::Mat bgr, depth, ids;
    renderer.Render(mesh, X_WC, &bgr, &depth, &ids);
    // The near box's centre pixel lies inside both silhouettes.
    const Eigen::Vector2d uv = HandProject(K, X_WC, X_near.translation());
    const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
    EXPECT_EQ(ids.at<int>(v, u), near_id);
    EXPECT_NEAR(depth.at<float>(v, u), 2.0 - 0.15, 1e-3);
    EXPECT_EQ(bgr.at<cv::Vec3b>(v, u)[0], 0);  // red-only colour: no blue from the sphere
    // The far sphere is still visible around the box.
    const Eigen::Vector2d uv_far = HandProject(K, X_WC, X_far.translation() + Eigen::Vector3d(-0.3, 0, 0));
    EXPECT_EQ(
        ids.at<int>(static_cast<int>(std::lround(uv_far.y())), static_cast<int>(std::lround(uv_far.x()))),
        far_id);
    // Every pixel of the near box is nearer than the sphere could be.
    EXPECT_GT(CountId(ids, near_id), 10000);
    EXPECT_GT(CountId(ids, far_id), 10000);
  }
}

TEST(Renderer, SphereOnThePrincipalAxisIsCentredOnThePrincipalPoint) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  Renderer renderer(K);
  const Eigen::Isometry3d X_WC = geometry::LookAt({0.3, -2.0, 1.4}, {0.1, 0.4, 0.9});
  Primitive s;
  s.shape = Primitive::Shape::kSphere;
  s.radius_m = 0.1;
  s.X_WG.translation() = X_WC * Eigen::Vector3d(0, 0, 1.8);
  SceneGeometry g;
  const int id = g.AddBody("ball", BodyKind::kSceneObject, ColorBgr{}, s);
  Mesh mesh;
  Tessellate(g, kAllKinds, TessellationOptions{24, 48, 24}, &mesh);
  cv::Mat bgr, ids;
  renderer.Render(mesh, X_WC, &bgr, nullptr, &ids);
  double su = 0, sv = 0, n = 0;
  for (int v = 0; v < ids.rows; ++v)
    for (int u = 0; u < ids.cols; ++u)
      if (ids.at<int>(v, u) == id) su += u, sv += v, n += 1;
  ASSERT_GT(n, 1000);
  EXPECT_NEAR(su / n, 597.2, 0.3);
  EXPECT_NEAR(sv / n, 322.1, 0.3);
}

TEST(Renderer, FloorThroughTheNearPlaneIsClippedToTheHorizon) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  Renderer renderer(K);
  SceneGeometry g;
  // A 40 m floor, camera 1.6 m above it looking level: most of the floor is behind the camera, yet
  // every row far enough below the horizon (v = cy) shows it and no row above the horizon does.
  const int floor = g.AddBody("floor", BodyKind::kSceneObject, ColorBgr{},
                              Box({40, 40, 0.02}, Eigen::Isometry3d(Eigen::Translation3d(0, 0, -0.01))));
  Mesh mesh;
  Tessellate(g, kAllKinds, {}, &mesh);
  const Eigen::Isometry3d X_WC = geometry::LookAt({0.0, 0.0, 1.6}, {5.0, 0.5, 1.6});
  cv::Mat bgr, ids;
  renderer.Render(mesh, X_WC, &bgr, nullptr, &ids);
  for (int u : {0, 300, 640, 1279}) {
    EXPECT_EQ(ids.at<int>(719, u), floor);
    EXPECT_EQ(ids.at<int>(500, u), floor);  // 13.9 m ahead, inside the floor's 20 m half-extent
    EXPECT_EQ(ids.at<int>(300, u), -1);
    EXPECT_EQ(ids.at<int>(0, u), -1);
  }
}

TEST(Renderer, OperatingRoomShowsEveryLinkAndObjectsInView) {
  const sim::RobotModel robot =
      sim::RobotModel::LoadFile(orbed::SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
  const sim::Scene scene = sim::LoadSceneFile(orbed::SourceTreePath(sim::kDefaultSceneRelativePath));
  Eigen::VectorXd q_deg(7);
  q_deg << 0, 35, 0, -70, 0, 45, 0;
  SceneGeometry g = SceneGeometry::MakeOperatingRoom(scene, robot, sim::DegToRad(q_deg), scene.X_WR);
  Mesh mesh;
  Tessellate(g, kAllKinds, {}, &mesh);
  Renderer renderer(geometry::Intrinsics::HoloLensPv());
  cv::Mat bgr, ids;
  renderer.Render(mesh, geometry::LookAt({1.7, -2.2, 1.7}, {0.25, -0.4, 1.1}), &bgr, nullptr, &ids);
  std::set<std::string> seen;
  for (int v = 0; v < ids.rows; ++v)
    for (int u = 0; u < ids.cols; ++u)
      if (ids.at<int>(v, u) >= 0) seen.insert(g.bodies()[ids.at<int>(v, u)].name);
  for (const char* name : {"iiwa_link_1", "iiwa_link_2", "iiwa_link_3", "iiwa_link_4", "iiwa_link_5", "floor",
                           "table_top", "robot_cart"})
    EXPECT_TRUE(seen.count(name)) << name;
  EXPECT_EQ(g.FindBody("virtual/iiwa_link_1"), -1);
  // Adjacent links are told apart by colour.
  const ColorBgr a = g.bodies()[g.FindBody("iiwa_link_3")].color;
  const ColorBgr b = g.bodies()[g.FindBody("iiwa_link_4")].color;
  EXPECT_TRUE(a.b != b.b || a.g != b.g || a.r != b.r);
}

TEST(Renderer, OverlayBlendsOnlyWhereTheHologramIs) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  Renderer renderer(K);
  SceneGeometry g;
  Eigen::Isometry3d X_WG = Eigen::Isometry3d::Identity();
  X_WG.translation() = Eigen::Vector3d(0, 0, 1.0);
  const int id =
      g.AddBody("holo", BodyKind::kVirtualRobot, ColorBgr{255, 255, 0}, Box({0.4, 0.4, 0.4}, X_WG));
  Mesh mesh;
  Tessellate(g, kAllKinds, {}, &mesh);
  const Eigen::Isometry3d X_WC = geometry::LookAt({0, -2.0, 1.0}, {0, 0, 1.0});
  cv::Mat image(K.height_px, K.width_px, CV_8UC3, cv::Scalar(10, 20, 30));
  cv::Mat ids;
  OverlayStyle style;
  renderer.RenderOverlay(mesh, X_WC, style, &image, &ids);
  const cv::Vec3b centre = image.at<cv::Vec3b>(322, 597);
  EXPECT_EQ(ids.at<int>(322, 597), id);
  EXPECT_GT(centre[0], 100);                                      // blended toward the hologram's colour
  EXPECT_LT(centre[2], 30);                                       // ... which has no red
  EXPECT_EQ(image.at<cv::Vec3b>(10, 10), cv::Vec3b(10, 20, 30));  // untouched outside
  EXPECT_EQ(ids.at<int>(10, 10), -1);
  // The silhouette is outlined in the edge colour: the left edge of the face, on the centre row.
  int left = 0;
  while (ids.at<int>(322, left) != id) ++left;
  const cv::Vec3b edge = image.at<cv::Vec3b>(322, left);
  EXPECT_GT(edge[2], 150);  // the edge colour has strong red, the face none
  // A second overlay after the first starts from a clean z-buffer.
  cv::Mat image2(K.height_px, K.width_px, CV_8UC3, cv::Scalar(10, 20, 30));
  renderer.RenderOverlay(mesh, X_WC, style, &image2);
  EXPECT_EQ(cv::norm(image, image2, cv::NORM_INF), 0);
}

TEST(Renderer, JpegRoundTripIsSmallAndFaithful) {
  const sim::RobotModel robot =
      sim::RobotModel::LoadFile(orbed::SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
  const sim::Scene scene = sim::LoadSceneFile(orbed::SourceTreePath(sim::kDefaultSceneRelativePath));
  SceneGeometry g = SceneGeometry::MakeOperatingRoom(scene, robot, Eigen::VectorXd::Zero(7), scene.X_WR);
  Mesh mesh;
  Tessellate(g, kAllKinds, {}, &mesh);
  Renderer renderer(geometry::Intrinsics::HoloLensPv());
  cv::Mat bgr;
  renderer.Render(mesh, geometry::LookAt({1.7, -2.2, 1.7}, {0.25, -0.4, 1.1}), &bgr);
  std::vector<std::uint8_t> jpeg;
  ASSERT_TRUE(EncodeJpeg(bgr, 85, &jpeg));
  EXPECT_LT(jpeg.size(), 300000u);
  EXPECT_EQ(jpeg[0], 0xFF);
  EXPECT_EQ(jpeg[1], 0xD8);
  const cv::Mat back = DecodeJpeg(jpeg);
  ASSERT_EQ(back.size(), bgr.size());
  ASSERT_EQ(back.type(), CV_8UC3);
  EXPECT_GT(cv::PSNR(back, bgr), 30.0);
  EXPECT_TRUE(DecodeJpeg({1, 2, 3}).empty());
}

}  // namespace
}  // namespace orbed::render
