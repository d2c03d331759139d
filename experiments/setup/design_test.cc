// The design catalog and each user's draw: the port geometry against the shipped scene's trocar
// (hand-computed), the draw's rules on a small hand-made catalog, the start-target relation on hand
// cases, the catalog file's round trip, and the shipped catalog's targets docking at their ports
// (forward kinematics).
#include "experiments/setup/design.h"

#include <cmath>
#include <fstream>
#include <set>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "base/units.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::setup {
namespace {

// The medium patient's umbilicus port is trocar_or.yaml's trocar: skin (0.1, 0, 1.02), tilted 15
// deg toward −x, docking 0.05 m out: (0.1 + 0.05 sin 15°, 0, 1.02 + 0.05 cos 15°).
TEST(DesignPorts, TheMediumUmbilicusIsTheShippedScenesTrocar) {
  const DesignSpec spec = DefaultDesignSpec();
  const CatalogPort c = PortOnPatient(spec, spec.ports[0], Eigen::Vector2d(0, 0), 1.02);
  const sim::Scene scene = sim::LoadSceneFile(SourceTreePath(sim::kDefaultSceneRelativePath));
  EXPECT_LT((c.p_WT - scene.trocar.p_WT).norm(), 1e-5);
  EXPECT_LT((c.insertion_direction_W - scene.trocar.insertion_direction_W).norm(), 1e-5);
  const double s = std::sin(15 * kDegToRad), k = std::cos(15 * kDegToRad);
  EXPECT_NEAR(c.p_WT.x(), 0.1 + 0.05 * s, 1e-12);
  EXPECT_NEAR(c.p_WT.z(), 1.02 + 0.05 * k, 1e-12);
  // The epigastric port (0.18 m cranial) tilts 15 deg toward the field's centre, now toward +x.
  const CatalogPort e = PortOnPatient(spec, spec.ports[1], Eigen::Vector2d(0, 0), 1.02);
  EXPECT_NEAR(e.p_W_skin.x(), 0.1 - 0.18, 1e-12);
  EXPECT_NEAR(e.insertion_direction_W.x(), s, 1e-12);
  EXPECT_NEAR(e.insertion_direction_W.z(), -k, 1e-12);
  // The right lower port (0.08, −0.10) points at the field (−0.08, 0): horizontally along (−0.16, 0.10).
  const CatalogPort r = PortOnPatient(spec, spec.ports[2], Eigen::Vector2d(0, 0), 1.02);
  const Eigen::Vector2d h = Eigen::Vector2d(-0.16, 0.10).normalized() * s;
  EXPECT_NEAR(r.insertion_direction_W.x(), h.x(), 1e-12);
  EXPECT_NEAR(r.insertion_direction_W.y(), h.y(), 1e-12);
  EXPECT_NEAR(r.insertion_direction_W.norm(), 1.0, 1e-12);
}

TEST(DesignRelation, SignsOfTheBendingJoints) {
  const std::vector<double> start = {0, 20, 0, -60, 0, 40, 0};
  EXPECT_EQ(BendingRelation(start, {90, 10, 50, -30, 0, 5, 9}), Relation::kSame);
  EXPECT_EQ(BendingRelation(start, {160, -25, 35, 71, 0, -83, -99}), Relation::kMirror);
  EXPECT_EQ(BendingRelation(start, {0, -20, 0, -60, 0, 40, 0}), Relation::kMixed);
  // A straight start joint (|q| <= 1 deg) has no sign: mixed whatever the target.
  EXPECT_EQ(BendingRelation({0, 0, 0, 0, 0, 0, 0}, start), Relation::kMixed);
  EXPECT_EQ(BendingSigns(start), "+-+");
  EXPECT_EQ(BendingSigns({0, 0.5, 0, 2, 0, -2, 0}), "0+-");
}

// A hand-made catalog: two patients (5 and 3 targets), three starts.
DesignCatalog SmallCatalog() {
  DesignCatalog c;
  c.patients = {{"a", "scene_a.yaml", ""}, {"b", "scene_b.yaml", ""}};
  for (int i = 1; i <= 5; ++i)
    c.targets.push_back(
        {"a/p/" + std::to_string(i), "a", "p", "+-+", {double(i), 20, 0, -60, 0, 40, 0}, 0.1, 0.1});
  for (int i = 1; i <= 3; ++i)
    c.targets.push_back(
        {"b/p/" + std::to_string(i), "b", "p", "-+-", {double(i), -20, 0, 60, 0, -40, 0}, 0.1, 0.1});
  c.starts = {{"s1", {0, 20, 0, -60, 0, 40, 0}, "", 0.1},
              {"s2", {0, 0, 0, 0, 0, 0, 0}, "", 0.1},
              {"s3", {0, -20, 0, 60, 0, -40, 0}, "", 0.1}};
  return c;
}

std::string Key(const UserDesign& d) {
  std::string key = d.patient;
  for (const DesignPair& p : d.pairs) key += "|" + p.start_id + ">" + p.target_id;
  return key;
}

TEST(DrawUserDesign, DeterministicPerSeedDistinctTargetsOfThePatientFromTheCatalog) {
  const DesignCatalog c = SmallCatalog();
  std::set<std::string> draws, patients, starts;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    const UserDesign d = DrawUserDesign(c, seed, 3);
    EXPECT_EQ(Key(d), Key(DrawUserDesign(c, seed, 3)));  // the same seed, the same draw
    draws.insert(Key(d));
    patients.insert(d.patient);
    ASSERT_EQ(d.pairs.size(), 3u);
    std::set<std::string> ids;
    for (const DesignPair& p : d.pairs) {
      ids.insert(p.target_id);
      starts.insert(p.start_id);
      // Every target is the catalog's, of the drawn patient, with its joints; every start too.
      bool found = false;
      for (const CatalogTarget& t : c.targets)
        found |= t.id == p.target_id && t.patient == d.patient && t.q_deg == p.target_deg;
      EXPECT_TRUE(found) << p.target_id;
      bool start = false;
      for (const CatalogStart& s : c.starts) start |= s.id == p.start_id && s.q_deg == p.start_deg;
      EXPECT_TRUE(start) << p.start_id;
    }
    EXPECT_EQ(ids.size(), 3u) << "targets without repetition";
    EXPECT_EQ(d.scene, c.FindPatient(d.patient)->scene);
  }
  // Different seeds differ: 40 seeds give many different draws, both patients, every start.
  EXPECT_GE(draws.size(), 30u);
  EXPECT_EQ(patients.size(), 2u);
  EXPECT_EQ(starts.size(), 3u);
}

TEST(DrawUserDesign, AGivenPatientKeepsTheStreamAndTooFewTargetsAreRefused) {
  const DesignCatalog c = SmallCatalog();
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const UserDesign d = DrawUserDesign(c, seed, 2);
    EXPECT_EQ(Key(DrawUserDesign(c, seed, 2, d.patient)), Key(d));
  }
  EXPECT_THROW(DrawUserDesign(c, 1, 4, std::string("b")), std::invalid_argument);  // b has 3
  EXPECT_THROW(DrawUserDesign(c, 1, 2, std::string("nobody")), std::invalid_argument);
  EXPECT_THROW(DrawUserDesign(c, 1, 0), std::invalid_argument);
  // K = all of a's targets: a permutation of them.
  const UserDesign all = DrawUserDesign(c, 3, 5, std::string("a"));
  std::set<std::string> ids;
  for (const DesignPair& p : all.pairs) ids.insert(p.target_id);
  EXPECT_EQ(ids.size(), 5u);
}

TEST(DesignFile, WrittenAndReadBack) {
  DesignCatalog c = SmallCatalog();
  c.command = "orbed-design catalog";
  CatalogPort port;
  port.patient = "a";
  port.port = "p";
  c.ports.push_back(port);
  const std::string path = ::testing::TempDir() + "/design.json";
  std::ofstream(path) << DesignCatalogJson(c);
  const DesignCatalog back = ReadDesignFile(path);
  EXPECT_EQ(DesignCatalogJson(back).substr(0, 40), DesignCatalogJson(c).substr(0, 40));
  ASSERT_EQ(back.targets.size(), c.targets.size());
  EXPECT_EQ(back.targets[6].id, "b/p/2");
  EXPECT_EQ(back.targets[6].q_deg, c.targets[6].q_deg);
  ASSERT_EQ(back.starts.size(), 3u);
  for (uint64_t seed : {1, 2, 3})
    EXPECT_EQ(Key(DrawUserDesign(back, seed, 3)), Key(DrawUserDesign(c, seed, 3)));
  // A target of a patient the file does not list is refused.
  std::string text = DesignCatalogJson(c);
  text.replace(text.find("\"patient\": \"b\""), 14, "\"patient\": \"z\"");
  std::ofstream(path) << text;
  EXPECT_THROW(ReadDesignFile(path), std::runtime_error);
}

// The shipped catalog: every target docks at its port (forward kinematics in the patient's scene),
// is in its branch and within the joint limits; every start is the same in every file.
TEST(ShippedDesign, EveryTargetDocksAtItsPort) {
  const DesignCatalog c = ReadDesignFile(SourceTreePath(kDefaultDesignRelativePath));
  ASSERT_EQ(c.patients.size(), 3u);
  EXPECT_GE(c.starts.size(), 4u);
  for (const DesignPatient& p : c.patients) {
    const sim::Scene scene = sim::LoadSceneFile(SourceTreePath(p.scene));
    const sim::RobotModel model =
        sim::LoadRobotForScene(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath), scene);
    int targets = 0;
    for (const CatalogTarget& t : c.targets) {
      if (t.patient != p.name) continue;
      ++targets;
      const CatalogPort* port = nullptr;
      for (const CatalogPort& q : c.ports) {
        if (q.patient == t.patient && q.port == t.port) port = &q;
      }
      ASSERT_NE(port, nullptr) << t.id;
      Eigen::VectorXd q(7);
      for (int i = 0; i < 7; ++i) q[i] = t.q_deg[i] * kDegToRad;
      EXPECT_EQ(model.ValidateJointVector(q), "") << t.id;
      const Eigen::Isometry3d X_WT = scene.X_WR * model.CalcToolTipPose(q);
      EXPECT_LT((X_WT.translation() - port->p_WT).norm(), 1e-3) << t.id;
      EXPECT_GT(X_WT.linear().col(2).dot(port->insertion_direction_W), std::cos(0.1 * kDegToRad)) << t.id;
      EXPECT_EQ(BendingSigns(t.q_deg), t.branch) << t.id;
      EXPECT_EQ(t.id.rfind(p.name + "/" + t.port + "/", 0), 0u) << t.id;
    }
    EXPECT_GE(targets, 3) << p.name << ": K = 3 must be drawable";
  }
}

}  // namespace
}  // namespace orbed::setup
