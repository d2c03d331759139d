// Oracle: hand-computed Table 1 statistics for two landmark pairs.
#include "geometry/misalignment.h"

#include <cmath>

#include <gtest/gtest.h>

namespace orbed::geometry {
namespace {

TEST(MisalignmentTest, TwoPairsMatchHandComputedTableOneColumns) {
  const std::vector<Eigen::Vector3d> real = {{0, 0, 0}, {1, 1, 1}};
  const std::vector<Eigen::Vector3d> virt = {{0.003, -0.004, 0}, {1.006, 1.008, 1}};
  const MisalignmentResult r = EvaluateMisalignment(real, virt);
  ASSERT_TRUE(r.valid) << r.reason;
  ASSERT_EQ(r.error_W_m.size(), 2u);
  EXPECT_TRUE(r.error_W_m[0].isApprox(Eigen::Vector3d(0.003, 0.004, 0), 1e-12));
  EXPECT_NEAR(r.error_norm_m[0], 0.005, 1e-15);
  EXPECT_NEAR(r.error_norm_m[1], 0.010, 1e-14);
  EXPECT_TRUE(r.mean_error_W_m.isApprox(Eigen::Vector3d(0.0045, 0.006, 0), 1e-12));
  EXPECT_NEAR(r.mean_error_norm_m, 0.0075, 1e-15);
  EXPECT_NEAR(r.mean_pair_distance_m, 0.0075, 1e-15);
  // Sample standard deviations: |a − b|/√2 per axis.
  EXPECT_NEAR(r.std_error_W_m.x(), 0.003 / std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(r.std_error_W_m.y(), 0.004 / std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(r.std_error_W_m.z(), 0.0, 1e-15);
  EXPECT_NEAR(r.std_error_norm_m, 0.005 / std::sqrt(2.0), 1e-15);
}

TEST(MisalignmentTest, BadInputIsRejectedWithAReason) {
  EXPECT_NE(EvaluateMisalignment({}, {}).reason.find("no landmark pairs"), std::string::npos);
  EXPECT_NE(EvaluateMisalignment({{0, 0, 0}}, {}).reason.find("virtual"), std::string::npos);
  EXPECT_NE(EvaluateMisalignment({{0, 0, 0}}, {{std::nan(""), 0, 0}}).reason.find("pair 0"),
            std::string::npos);
}

}  // namespace
}  // namespace orbed::geometry
