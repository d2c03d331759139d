// Oracles: rays constructed through a known point; skew lines whose least-squares point and gap
// are known in closed form.
#include "geometry/triangulation.h"

#include <cmath>

#include <gtest/gtest.h>

#include "base/units.h"

namespace orbed::geometry {
namespace {

TEST(TriangulationTest, TwoRaysThroughAKnownPointRecoverIt) {
  const Eigen::Vector3d p_WX(0.3, -0.2, 1.5);
  const std::vector<Eigen::Vector3d> h = {{0, 0, 0}, {1.0, 0.1, 0.2}};
  std::vector<Eigen::Vector3d> u;
  for (const auto& hi : h) u.push_back((p_WX - hi).normalized());
  const TriangulationResult r = TriangulateRays(h, u);
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_LT((r.p_W - p_WX).norm(), 1e-12);
  EXPECT_LT(r.gap_m, 1e-12);
  const double expected_angle_deg = std::acos(u[0].dot(u[1])) * 180.0 / kPi;
  EXPECT_NEAR(r.ray_angle_deg, expected_angle_deg, 1e-9);
  ASSERT_EQ(r.depth_m.size(), 2u);
  EXPECT_NEAR(r.depth_m[0], (p_WX - h[0]).norm(), 1e-12);
  EXPECT_NEAR(r.depth_m[1], (p_WX - h[1]).norm(), 1e-12);
}

TEST(TriangulationTest, ThreeRaysThroughAKnownPointRecoverIt) {
  const Eigen::Vector3d p_WX(-1.0, 2.0, 0.5);
  const std::vector<Eigen::Vector3d> h = {{0, 0, 1.7}, {0.5, 0.2, 1.6}, {-0.4, 0.3, 1.8}};
  std::vector<Eigen::Vector3d> u;
  for (const auto& hi : h) u.push_back((p_WX - hi).normalized());
  const TriangulationResult r = TriangulateRays(h, u);
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_LT((r.p_W - p_WX).norm(), 1e-12);
}

TEST(TriangulationTest, SkewRaysGiveTheMidpointAndTheirHalfDistanceAsGap) {
  // Line 1 along x at z = −d, line 2 along y at z = +d: closest point (0, 0, 0), each line d away.
  const double d = 0.01;
  const TriangulationResult r =
      TriangulateRays({{-1, 0, -d}, {0, -1, d}}, {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()});
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_LT(r.p_W.norm(), 1e-15);
  EXPECT_NEAR(r.gap_m, d, 1e-15);
  EXPECT_NEAR(r.ray_angle_deg, 90.0, 1e-12);
}

TEST(TriangulationTest, ParallelAndNearParallelRaysAreRejected) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  TriangulationResult r = TriangulateRays({{0, 0, 0}, {1, 0, 0}}, {z, z});
  EXPECT_FALSE(r.valid);
  EXPECT_NE(r.reason.find("parallel"), std::string::npos);
  // 0.5° apart with the default 2° threshold.
  const Eigen::Vector3d tilted(std::sin(0.5 * kPi / 180), 0, std::cos(0.5 * kPi / 180));
  r = TriangulateRays({{0, 0, 0}, {1, 0, 0}}, {z, tilted});
  EXPECT_FALSE(r.valid);
  EXPECT_NEAR(r.ray_angle_deg, 0.5, 1e-9);
  // Anti-parallel lines are parallel too.
  r = TriangulateRays({{0, 0, 0}, {1, 0, 0}}, {z, -z});
  EXPECT_FALSE(r.valid);
  EXPECT_NE(r.reason.find("parallel"), std::string::npos);
}

TEST(TriangulationTest, PointBehindAnOriginIsRejected) {
  // The lines meet at X, but both rays point away from it.
  const Eigen::Vector3d p_WX(0.5, 0, -1.0);
  const std::vector<Eigen::Vector3d> h = {{0, 0, 0}, {1, 0, 0}};
  const std::vector<Eigen::Vector3d> u = {(h[0] - p_WX).normalized(), (h[1] - p_WX).normalized()};
  const TriangulationResult r = TriangulateRays(h, u);
  EXPECT_FALSE(r.valid);
  EXPECT_NE(r.reason.find("behind the origin of ray 0"), std::string::npos);
  EXPECT_LT((r.p_W - p_WX).norm(), 1e-12);
}

TEST(TriangulationTest, BadInputIsRejectedWithAReason) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  EXPECT_NE(TriangulateRays({{0, 0, 0}}, {z}).reason.find("at least 2"), std::string::npos);
  EXPECT_NE(TriangulateRays({{0, 0, 0}, {1, 0, 0}}, {z}).reason.find("directions"), std::string::npos);
  EXPECT_NE(TriangulateRays({{0, 0, 0}, {1, 0, 0}}, {z, 2.0 * Eigen::Vector3d::UnitX()}).reason.find("norm"),
            std::string::npos);
  EXPECT_NE(TriangulateRays({{0, 0, std::nan("")}, {1, 0, 0}}, {z, Eigen::Vector3d::UnitX()})
                .reason.find("non-finite"),
            std::string::npos);
}

}  // namespace
}  // namespace orbed::geometry
