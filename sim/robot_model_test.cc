// Tests of the URDF robot model against an independent standard-DH evaluation of the iiwa 7.
#include "sim/robot_model.h"
#include "base/source_paths.h"
#include "base/units.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

namespace orbed::sim {
namespace {

RobotModel LoadIiwa() {
  return RobotModel::LoadFile(orbed::SourceTreePath(RobotModel::kDefaultUrdfRelativePath));
}

// The iiwa 7 R800 data-sheet DH parameters, evaluated by hand:
// T_{i-1,i} = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i).
Eigen::Matrix4d DhTransform(double theta, double d, double a, double alpha) {
  const double ct = std::cos(theta), st = std::sin(theta), ca = std::cos(alpha), sa = std::sin(alpha);
  Eigen::Matrix4d T;
  T << ct, -st * ca, st * sa, a * ct, st, ct * ca, -ct * sa, a * st, 0, sa, ca, d, 0, 0, 0, 1;
  return T;
}

// DH frames 0..7 (frame 7 = flange).
std::vector<Eigen::Matrix4d> DhFrames(const Eigen::VectorXd& q) {
  const double d[7] = {0.34, 0, 0.4, 0, 0.4, 0, 0.126};
  const double alpha[7] = {-kPi / 2, kPi / 2, kPi / 2, -kPi / 2, -kPi / 2, kPi / 2, 0};
  std::vector<Eigen::Matrix4d> F{Eigen::Matrix4d::Identity()};
  for (int i = 0; i < 7; ++i) F.push_back(F.back() * DhTransform(q[i], d[i], 0.0, alpha[i]));
  return F;
}

Eigen::VectorXd Deg(std::initializer_list<double> v) {
  Eigen::VectorXd q(v.size());
  int i = 0;
  for (double x : v) q[i++] = x * kPi / 180.0;
  return q;
}

TEST(RobotModelTest, LoadsSevenJointsWithDataSheetLimits) {
  const RobotModel m = LoadIiwa();
  ASSERT_EQ(m.num_joints(), 7);
  const double limit_deg[7] = {170, 120, 170, 120, 170, 120, 175};
  const double speed_deg[7] = {98, 98, 100, 130, 140, 180, 180};
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(m.joints()[i].upper_rad * 180 / kPi, limit_deg[i], 1e-9) << i;
    EXPECT_NEAR(m.joints()[i].lower_rad * 180 / kPi, -limit_deg[i], 1e-9) << i;
    EXPECT_NEAR(m.joints()[i].velocity_rad_per_s * 180 / kPi, speed_deg[i], 1e-9) << i;
  }
  EXPECT_NEAR(m.tool_length_m(), 0.25, 1e-12);
  EXPECT_EQ(m.links()[m.flange_link()].name, "iiwa_link_ee");
  EXPECT_EQ(m.links()[m.tool_link()].name, "iiwa_tool");
}

TEST(RobotModelTest, ZeroPoseFlangeAt1266Upright) {
  const RobotModel m = LoadIiwa();
  const Eigen::Isometry3d X_RF = m.CalcFlangePose(Eigen::VectorXd::Zero(7));
  EXPECT_TRUE(X_RF.translation().isApprox(Eigen::Vector3d(0, 0, 1.266), 1e-12))
      << X_RF.translation().transpose();
  EXPECT_TRUE(X_RF.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  const Eigen::Isometry3d X_RT = m.CalcToolTipPose(Eigen::VectorXd::Zero(7));
  EXPECT_NEAR(X_RT.translation().z(), 1.266 + 0.25, 1e-12);
}

TEST(RobotModelTest, FlangeAndJointFramesMatchDhOracle) {
  const RobotModel m = LoadIiwa();
  const std::vector<Eigen::VectorXd> qs = {
      Deg({0, 0, 0, 0, 0, 0, 0}),
      Deg({170, 120, 170, 120, 170, 120, 175}),
      Deg({-170, -120, -170, -120, -170, -120, -175}),
      Deg({30, -45, 60, 90, -20, 75, -110}),
      Deg({-120, 100, -30, -115, 150, -60, 20}),
      Deg({10, 20, 30, 40, 50, 60, 70}),
  };
  for (const auto& q : qs) {
    const auto F = DhFrames(q);
    const auto X = m.CalcLinkPoses(q);
    const Eigen::Matrix4d X_RF = X[m.flange_link()].matrix();
    EXPECT_TRUE(X_RF.isApprox(F[7], 1e-12)) << "q=" << q.transpose() << "\n" << X_RF << "\n" << F[7];
    // Link i+1's frame is DH frame i turned by q_{i+1}: same origin, same z (the joint axis).
    for (int i = 0; i < 7; ++i) {
      const Eigen::Isometry3d& X_RL = X[m.joints()[i].link];
      EXPECT_LT((X_RL.translation() - F[i].block<3, 1>(0, 3)).norm(), 1e-12);
      EXPECT_TRUE(X_RL.linear().col(2).isApprox(F[i].block<3, 1>(0, 2), 1e-12));
    }
  }
}

// Updating the poses for one joint's new angle gives CalcLinkPoses' poses bit for bit, and leaves
// the links the joint does not move (those before it, those past last_link) as they were.
TEST(RobotModelTest, UpdateLinkPosesForJointIsCalcLinkPosesBitForBit) {
  const RobotModel model = LoadIiwa();
  Eigen::VectorXd q(7);
  q << 0.3, -0.7, 1.1, -1.4, 0.5, 0.9, -2.0;
  const std::vector<Eigen::Isometry3d> X_old = model.CalcLinkPoses(q);
  for (int j = 0; j < model.num_joints(); ++j) {
    Eigen::VectorXd q_new = q;
    q_new[j] = -0.123456789 + 0.2 * j;
    const std::vector<Eigen::Isometry3d> X_new = model.CalcLinkPoses(q_new);
    std::vector<Eigen::Isometry3d> X = X_old;
    model.UpdateLinkPosesForJoint(q_new, j, model.num_links() - 1, &X);
    for (int i = 0; i < model.num_links(); ++i)
      EXPECT_TRUE(X[i].matrix() == X_new[i].matrix()) << "joint " << j << ", link " << i;
    const int last = model.joints()[j].link;  // only the joint's child link
    X = X_old;
    model.UpdateLinkPosesForJoint(q_new, j, last, &X);
    for (int i = 0; i < model.num_links(); ++i) {
      const Eigen::Isometry3d& expected = i == last ? X_new[i] : X_old[i];
      EXPECT_TRUE(X[i].matrix() == expected.matrix()) << "joint " << j << ", link " << i;
    }
  }
  std::vector<Eigen::Isometry3d> wrong(2);
  EXPECT_THROW(model.UpdateLinkPosesForJoint(q, 0, 3, &wrong), std::invalid_argument);
}

TEST(RobotModelTest, JacobianMatchesFiniteDifferences) {
  const RobotModel m = LoadIiwa();
  const Eigen::VectorXd q = Deg({25, -35, 50, 70, -40, 55, 10});
  const int tip = m.tool_tip_link();
  const Eigen::MatrixXd J = m.CalcJacobian(q, tip);
  const double h = 1e-7;
  const Eigen::Isometry3d X0 = m.CalcLinkPoses(q)[tip];
  for (int j = 0; j < 7; ++j) {
    Eigen::VectorXd qp = q;
    qp[j] += h;
    const Eigen::Isometry3d X1 = m.CalcLinkPoses(qp)[tip];
    const Eigen::Vector3d v = (X1.translation() - X0.translation()) / h;
    const Eigen::AngleAxisd aa(X1.linear() * X0.linear().transpose());
    const Eigen::Vector3d w = aa.axis() * aa.angle() / h;
    EXPECT_TRUE((J.block<3, 1>(3, j) - v).norm() < 1e-6) << j;
    EXPECT_TRUE((J.block<3, 1>(0, j) - w).norm() < 1e-6) << j;
  }
}

TEST(RobotModelTest, SetToolLengthMovesTipAndStretchesShaft) {
  RobotModel m = LoadIiwa();
  m.SetToolLength(0.4);
  const Eigen::VectorXd q = Deg({10, 20, 30, 40, 50, 60, 70});
  const auto X = m.CalcLinkPoses(q);
  const Eigen::Isometry3d X_FT = X[m.flange_link()].inverse() * X[m.tool_tip_link()];
  EXPECT_TRUE(X_FT.translation().isApprox(Eigen::Vector3d(0, 0, 0.4), 1e-12));
  bool found = false;
  for (const auto& g : m.links()[m.tool_link()].collision) {
    if (g.name == "shaft") {
      found = true;
      EXPECT_NEAR(g.length_m, 0.35, 1e-12);  // from 0.05 to 0.40
      EXPECT_NEAR(g.X_LG.translation().z(), 0.225, 1e-12);
    }
    if (g.name == "adaptor") {
      EXPECT_NEAR(g.length_m, 0.05, 1e-12);
    }
  }
  EXPECT_TRUE(found);
  EXPECT_THROW(m.SetToolLength(0.04), std::invalid_argument);
  EXPECT_THROW(m.SetToolLength(std::nan("")), std::invalid_argument);
}

// FuseCapsules: the shipped model's capsules (links 1-5, one each) fuse; a hand-made tilted triple
// fuses into one capsule listed first; a cap 10 nm off its end face, or 10 nm too large, does not.
TEST(RobotModelTest, FuseCapsulesRecognisesExactTriplesOnly) {
  using Kind = CollisionPrimitive::Kind;
  const RobotModel m = LoadIiwa();
  for (int l = 1; l <= 5; ++l) {
    const int link = m.FindLink("iiwa_link_" + std::to_string(l));
    ASSERT_GE(link, 0);
    const std::vector<CollisionPrimitive> fused = FuseCapsules(m.links()[link].collision);
    int capsules = 0, spheres = 0;
    for (const auto& g : fused) {
      capsules += g.kind == Kind::kCapsule;
      spheres += g.kind == Kind::kSphere;
    }
    EXPECT_EQ(capsules, 1) << "iiwa_link_" << l;
    EXPECT_EQ(spheres, 0) << "iiwa_link_" << l;
  }

  CollisionPrimitive box;
  box.kind = Kind::kBox;
  box.size_m = Eigen::Vector3d(0.1, 0.2, 0.3);
  CollisionPrimitive cylinder;
  cylinder.kind = Kind::kCylinder;
  cylinder.name = "shaft";
  cylinder.radius_m = 0.05;
  cylinder.length_m = 0.3;
  cylinder.X_LG.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  cylinder.X_LG.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  const Eigen::Vector3d axis = cylinder.X_LG.linear().col(2);
  CollisionPrimitive cap_a, cap_b;
  cap_a.kind = cap_b.kind = Kind::kSphere;
  cap_a.radius_m = cap_b.radius_m = 0.05;
  cap_a.X_LG.translation() = Eigen::Vector3d(0.1, -0.2, 0.3) + 0.15 * axis;
  cap_b.X_LG.translation() = Eigen::Vector3d(0.1, -0.2, 0.3) - 0.15 * axis;

  const std::vector<CollisionPrimitive> fused = FuseCapsules({box, cap_a, cylinder, cap_b});
  ASSERT_EQ(fused.size(), 2u);
  EXPECT_EQ(fused[0].kind, Kind::kCapsule);
  EXPECT_EQ(fused[0].name, "shaft");
  EXPECT_EQ(fused[0].length_m, 0.3);
  EXPECT_EQ(fused[0].radius_m, 0.05);
  EXPECT_TRUE(fused[0].X_LG.isApprox(cylinder.X_LG, 0));
  EXPECT_EQ(fused[1].kind, Kind::kBox);

  CollisionPrimitive off = cap_b;
  off.X_LG.translation() += 1e-8 * Eigen::Vector3d::UnitX();
  EXPECT_EQ(FuseCapsules({cylinder, cap_a, off}).size(), 3u);
  CollisionPrimitive larger = cap_b;
  larger.radius_m += 1e-8;
  EXPECT_EQ(FuseCapsules({cylinder, cap_a, larger}).size(), 3u);
  // One sphere caps one capsule: two cylinders sharing an end face, three spheres.
  CollisionPrimitive next = cylinder;
  next.X_LG.translation() += 0.3 * axis;
  CollisionPrimitive cap_c = cap_a;
  cap_c.X_LG.translation() += 0.3 * axis;
  const std::vector<CollisionPrimitive> chain = FuseCapsules({cylinder, next, cap_a, cap_b, cap_c});
  ASSERT_EQ(chain.size(), 3u);
  EXPECT_EQ(chain[0].kind, Kind::kCapsule);
  EXPECT_EQ(chain[1].kind, Kind::kCylinder);
  EXPECT_EQ(chain[2].kind, Kind::kSphere);
}

TEST(RobotModelTest, ValidateJointVectorNamesTheJoint) {
  const RobotModel m = LoadIiwa();
  EXPECT_EQ(m.ValidateJointVector(Deg({170, 120, 170, 120, 170, 120, 175})), "");
  EXPECT_NE(m.ValidateJointVector(Deg({0, 121, 0, 0, 0, 0, 0})).find("iiwa_joint_2"), std::string::npos);
  EXPECT_NE(m.ValidateJointVector(Deg({0, 0, 0})).find("expected 7"), std::string::npos);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
  q[4] = std::nan("");
  EXPECT_NE(m.ValidateJointVector(q).find("iiwa_joint_5"), std::string::npos);
}

TEST(RobotModelTest, AdjacencyFollowsJointsAndFixedLinks) {
  const RobotModel m = LoadIiwa();
  auto body = [&](const char* n) { return m.links()[m.FindLink(n)].body; };
  EXPECT_EQ(body("iiwa_link_7"), body("iiwa_tool"));
  EXPECT_TRUE(m.BodiesAdjacent(body("iiwa_link_6"), body("iiwa_tool")));
  EXPECT_FALSE(m.BodiesAdjacent(body("iiwa_link_5"), body("iiwa_tool")));
  EXPECT_EQ(m.BodySeparation(body("iiwa_link_0"), body("iiwa_tool")), 7);
}

std::string Expect(const std::string& xml) {
  try {
    RobotModel::LoadString(xml, "bad.urdf");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

// TinyXML 2.6 skips a UTF-8 character by its lead byte's length: a lead byte at the end made it read
// past the text (fuzz_urdf); the sanitizer build catches a regression here.
TEST(RobotModelTest, TextThatIsNotUtf8IsRefusedBeforeAnyXmlParser) {
  std::string e = Expect("<robot name='r'><link name='a'><visual><origin xyz=\"0 0 \xDC");
  EXPECT_NE(e.find("bad.urdf: byte 56 is not valid UTF-8 text"), std::string::npos) << e;
  e = Expect(std::string("<robot name='r'>\0</robot>", 25));
  EXPECT_NE(e.find("byte 16 is not valid UTF-8"), std::string::npos) << e;
}

// urdfdom 3.0.1 would leak a reference cycle on these (the sanitizer build's LeakSanitizer checks that
// none is made); the loader refuses them first and names the loop.
TEST(RobotModelTest, JointLoopsAreRefusedBeforeUrdfdomLinksThem) {
  const std::string links = "<robot name='r'><link name='a'/><link name='b'/><link name='c'/>";
  auto joint = [](const char* name, const char* parent, const char* child) {
    return std::string("<joint name='") + name + "' type='fixed'><parent link='" + parent +
           "'/><child link='" + child + "'/></joint>";
  };
  std::string e = Expect(links + joint("j1", "a", "b") + joint("j2", "b", "b") + "</robot>");
  EXPECT_NE(e.find("bad.urdf: the joints form a loop (a URDF must be a tree): 'b' -> 'b'"), std::string::npos)
      << e;
  e = Expect(links + joint("j1", "a", "b") + joint("j2", "b", "c") + joint("j3", "c", "a") + "</robot>");
  EXPECT_NE(e.find("'a' -> 'b' -> 'c' -> 'a'"), std::string::npos) << e;
  // A long chain closed into a loop at its end; beyond 1000 joints the file is refused for its size.
  auto chain = [&joint](int joints) {
    std::string xml = "<robot name='r'>";
    for (int i = 0; i <= joints; ++i) xml += "<link name='l" + std::to_string(i) + "'/>";
    for (int i = 0; i < joints; ++i) {
      xml += joint(("j" + std::to_string(i)).c_str(), ("l" + std::to_string(i)).c_str(),
                   ("l" + std::to_string(i + 1)).c_str());
    }
    return xml;
  };
  e = Expect(chain(998) + joint("back", "l998", "l997") + "</robot>");
  EXPECT_NE(e.find("'l997' -> 'l998' -> 'l997'"), std::string::npos) << e.substr(0, 200);
  e = Expect(chain(1001) + "</robot>");
  EXPECT_NE(e.find("more than 1000 joints"), std::string::npos) << e.substr(0, 200);
  // A chain is not a loop: it gets past the check to the flange check.
  e = Expect(links + joint("j1", "a", "b") + joint("j2", "b", "c") + "</robot>");
  EXPECT_EQ(e.find("loop"), std::string::npos) << e;
}

TEST(RobotModelTest, BadUrdfsAreRejectedWithTheElement) {
  const std::string head = "<robot name='r'><link name='a'/><link name='iiwa_link_ee'/>";
  EXPECT_NE(Expect("<robot").find("bad.urdf"), std::string::npos);
  std::string e = Expect(head +
                         "<joint name='j1' type='continuous'><parent link='a'/><child link='iiwa_link_ee'/>"
                         "<axis xyz='0 0 1'/></joint></robot>");
  EXPECT_NE(e.find("bad.urdf: joint 'j1'"), std::string::npos) << e;
  e = Expect(head +
             "<joint name='j1' type='revolute'><parent link='a'/><child link='iiwa_link_ee'/>"
             "<axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='0'/></joint></robot>");
  EXPECT_NE(e.find("velocity"), std::string::npos) << e;
  e = Expect(
      "<robot name='r'><link name='a'><collision><geometry><mesh filename='x.stl'/></geometry></collision>"
      "</link><link name='iiwa_link_ee'/><joint name='j1' type='revolute'><parent link='a'/>"
      "<child link='iiwa_link_ee'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>");
  EXPECT_NE(e.find("link 'a'"), std::string::npos) << e;
  EXPECT_NE(
      Expect(
          "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'><parent "
          "link='a'/><child link='b'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>")
          .find("iiwa_link_ee"),
      std::string::npos);
  EXPECT_THROW(RobotModel::LoadFile("/nonexistent/x.urdf"), std::runtime_error);
}

}  // namespace
}  // namespace orbed::sim
