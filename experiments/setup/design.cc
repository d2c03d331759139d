#include "experiments/setup/design.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "base/json.h"
#include "base/json_fields.h"
#include "base/random.h"
#include "base/source_paths.h"
#include "base/units.h"
#include "sim/collision_world.h"
#include "sim/scene.h"
#include "sim/trocar_plan.h"

namespace orbed::setup {

DesignSpec DefaultDesignSpec() {
  DesignSpec s;
  // The torso's depth is the supine sagittal abdominal diameter (SAD) of US adults, NHANES
  // 2011-2012 (Kahn et al., PLoS ONE 9(10):e108707, 2014, both sexes): 5th percentile 16.4 cm,
  // median 21.9 cm, 75th 25.2 cm (the 95th, 30.5 cm, puts the abdomen into the alignment configurations of
  // experiments/viraal/viraal.yaml). The widths (0.36, 0.42, 0.48 m) are chosen. Scenes:
  // sim/models/scenes/trocar_or{_small,,_large}.yaml.
  const std::string sad = "torso depth = supine sagittal abdominal diameter, Kahn et al. PLoS ONE 2014 ";
  s.patients = {
      {"small", "sim/models/scenes/trocar_or_small.yaml",
       sad + "5th percentile (16.4 cm); width 0.36 m chosen"},
      {"medium", "sim/models/scenes/trocar_or.yaml", sad + "median (21.9 cm; 22 cm); width 0.42 m chosen"},
      {"large", "sim/models/scenes/trocar_or_large.yaml",
       sad + "75th percentile (25.2 cm; the 95th, 30.5 cm, meets the alignment moves); width 0.48 m chosen"},
  };
  // Ports after the usual laparoscopic layouts (the camera port at the umbilicus; an epigastric
  // port as in cholecystectomy; lower-quadrant ports lateral to the rectus sheath as in
  // gynaecological laparoscopy and appendectomy). The offsets are chosen, not measured. W: +x
  // toward the feet, −y the patient's right (the robot's side).
  s.ports = {
      {"umbilicus", {0.0, 0.0}, "the camera port of trocar_or.yaml"},
      {"epigastric", {-0.18, 0.0}, "chosen: 18 cm cranial of the umbilicus, midline"},
      {"right_lower", {0.08, -0.10}, "chosen: 8 cm caudal, 10 cm to the patient's right (robot side)"},
      {"left_lower", {0.08, 0.10}, "chosen: 8 cm caudal, 10 cm to the patient's left"},
  };
  // Parked configurations. Joint 2 > 0 leans the arm toward the table (the base faces +y).
  s.starts = {
      {"ready",
       {0, 20, 0, -60, 0, 40, 0},
       "the study's former single start: leaning over the table, elbow and wrist bent, ready to be guided"},
      {"ready_away",
       {0, -20, 0, 60, 0, -40, 0},
       "the mirror of ready (joints 2, 4, 6 negated): leaning back from the table, as after a retreat"},
      {"candle",
       {0, 0, 0, 0, 0, 0, 0},
       "the arm's zero: stretched vertically (KUKA's 'candle'), as powered up"},
      {"folded",
       {0, -30, 0, 100, 0, -60, 0},
       "chosen: folded back over its cart, elbow up, as wheeled in (not KUKA's published transport pose)"},
      {"aside",
       {-90, 20, 0, -60, 0, 40, 0},
       "the ready pose turned toward the foot end, out of the surgeon's way at the table's side"},
  };
  return s;
}

const DesignPatient* DesignCatalog::FindPatient(const std::string& name) const {
  for (const DesignPatient& p : patients) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

CatalogPort PortOnPatient(const DesignSpec& spec, const DesignPort& port, const Eigen::Vector2d& centre_xy_m,
                          double top_z_m) {
  const Eigen::Vector2d umbilicus = centre_xy_m + spec.umbilicus_offset_m;
  const Eigen::Vector2d skin = umbilicus + port.offset_m;
  const Eigen::Vector2d toward = umbilicus + spec.field_offset_m - skin;
  // Horizontal unit toward the field's centre (none when the port is on it: straight down).
  const Eigen::Vector2d h =
      toward.norm() > 1e-9 ? Eigen::Vector2d(toward.normalized()) : Eigen::Vector2d::Zero();
  const double tilt = (toward.norm() > 1e-9 ? spec.port_tilt_deg : 0.0) * kDegToRad;
  CatalogPort c;
  c.port = port.name;
  c.p_W_skin = Eigen::Vector3d(skin.x(), skin.y(), top_z_m);
  c.insertion_direction_W = Eigen::Vector3d(std::sin(tilt) * h.x(), std::sin(tilt) * h.y(), -std::cos(tilt));
  c.p_WT = c.p_W_skin - spec.stand_off_m * c.insertion_direction_W;
  return c;
}

namespace {

Eigen::VectorXd Rad(const std::vector<double>& q_deg) {
  Eigen::VectorXd q(q_deg.size());
  for (size_t i = 0; i < q_deg.size(); ++i) q[i] = q_deg[i] * kDegToRad;
  return q;
}

std::vector<double> Deg(const Eigen::VectorXd& q_rad) {
  std::vector<double> q;
  for (Eigen::Index i = 0; i < q_rad.size(); ++i) q.push_back(q_rad[i] * kRadToDeg);
  return q;
}

// The smallest CollisionWorld distance [m] along the straight joint-space segment a -> b, sampled
// every step_deg of the largest joint's travel (both ends included).
double SegmentClearance(sim::CollisionWorld* world, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                        double step_deg) {
  const double travel_deg = (b - a).cwiseAbs().maxCoeff() * kRadToDeg;
  const int n = std::max(1, static_cast<int>(std::ceil(travel_deg / step_deg)));
  double smallest = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= n; ++i)
    smallest = std::min(smallest, world->Check(a + (b - a) * (double(i) / n)).min_distance_m);
  return smallest;
}

const sim::SceneObject& Torso(const sim::Scene& scene, const std::string& name) {
  for (const sim::SceneObject& o : scene.objects) {
    if (o.name == name && o.shape == sim::SceneObject::Shape::kBox) return o;
  }
  throw std::runtime_error(scene.source + ": no box named " + name + " (the patient's torso)");
}

// The 8 sign patterns of joints 2, 4, 6, in a fixed order: "+-+" (the former start's) first.
std::vector<std::vector<int>> Branches(int num_joints) {
  std::vector<std::vector<int>> out;
  for (int s2 : {1, -1}) {
    for (int s4 : {-1, 1}) {
      for (int s6 : {1, -1}) {
        std::vector<int> signs(num_joints, 0);
        signs[1] = s2;
        signs[3] = s4;
        signs[5] = s6;
        out.push_back(signs);
      }
    }
  }
  return out;
}

}  // namespace

DesignCatalog MakeDesignCatalog(const DesignSpec& spec, const std::string& urdf_path,
                                const std::string& source_root, const std::string& command) {
  DesignCatalog catalog;
  catalog.command = command;
  catalog.patients = spec.patients;
  catalog.spec = spec;
  std::vector<sim::Scene> scenes;
  for (const DesignPatient& p : spec.patients)
    scenes.push_back(sim::LoadSceneFile((std::filesystem::path(source_root) / p.scene).string()));
  // The starts and the alignment configurations: collision-free in every patient's scene, and the
  // segments the conductor moves along between them (alignment 1 -> 2 -> ... -> last -> start).
  for (size_t s = 0; s < spec.starts.size(); ++s)
    catalog.starts.push_back({spec.starts[s].name, spec.starts[s].q_deg, spec.starts[s].why,
                              std::numeric_limits<double>::infinity()});
  for (size_t p = 0; p < scenes.size(); ++p) {
    const sim::RobotModel model = sim::LoadRobotForScene(urdf_path, scenes[p]);
    sim::CollisionWorld world(model, &scenes[p]);
    for (CatalogStart& start : catalog.starts) {
      const double c = world.Check(Rad(start.q_deg)).min_distance_m;
      start.clearance_m = std::min(start.clearance_m, c);
      if (c < spec.min_clearance_m) {
        throw std::runtime_error("start " + start.id + ": clearance " + std::to_string(c) + " m in " +
                                 scenes[p].source + ", less than " + std::to_string(spec.min_clearance_m));
      }
      // To and from the alignment's first and last configurations and every other start (the
      // sim's first configuration, its zero, is the candle start's).
      std::vector<std::pair<std::string, std::vector<double>>> others;
      if (!spec.alignment_deg.empty()) {
        others.push_back({"the first alignment configuration", spec.alignment_deg.front()});
        others.push_back({"the last alignment configuration", spec.alignment_deg.back()});
      }
      for (const DesignStart& other : spec.starts) others.push_back({"start " + other.name, other.q_deg});
      for (const auto& [name, q_deg] : others) {
        const double path = SegmentClearance(&world, Rad(q_deg), Rad(start.q_deg), spec.path_step_deg);
        if (path < spec.path_clearance_m) {
          throw std::runtime_error("start " + start.id + ": the move to " + name + " comes " +
                                   std::to_string(path) + " m close in " + scenes[p].source);
        }
      }
    }
    for (size_t a = 0; a + 1 < spec.alignment_deg.size(); ++a) {
      const double path = SegmentClearance(&world, Rad(spec.alignment_deg[a]), Rad(spec.alignment_deg[a + 1]),
                                           spec.path_step_deg);
      if (path < spec.path_clearance_m) {
        throw std::runtime_error("alignment configuration " + std::to_string(a + 1) + " -> " +
                                 std::to_string(a + 2) + " comes " + std::to_string(path) + " m close in " +
                                 scenes[p].source);
      }
    }
  }
  // The targets of every (patient, port), one per branch.
  for (size_t p = 0; p < scenes.size(); ++p) {
    const sim::SceneObject& torso = Torso(scenes[p], spec.torso_object);
    const Eigen::Vector3d centre = torso.X_WO.translation();
    const double top_z = centre.z() + torso.size_m.z() / 2;
    for (const DesignPort& port : spec.ports) {
      CatalogPort c = PortOnPatient(spec, port, centre.head<2>(), top_z);
      c.patient = spec.patients[p].name;
      sim::Scene scene = scenes[p];
      scene.trocar.p_WT = c.p_WT;
      scene.trocar.insertion_direction_W = c.insertion_direction_W;
      const sim::RobotModel model = sim::LoadRobotForScene(urdf_path, scene);
      sim::CollisionWorld world(model, &scene);
      int k = 0;
      for (const std::vector<int>& signs : Branches(model.num_joints())) {
        ++c.branches_tried;
        sim::TrocarPlanOptions o;
        o.num_targets = 1;
        o.min_clearance_m = spec.min_clearance_m;
        o.min_bend_deg = spec.min_bend_deg;
        o.seed = spec.seed;
        o.starts = spec.ik_starts;
        o.joint_signs = signs;
        std::vector<sim::PlannedTarget> found;
        try {
          found = sim::PlanTrocarTargets(model, scene, o);
        } catch (const std::runtime_error&) {
          continue;  // no docking configuration in this branch
        }
        ++c.branches_found;
        CatalogTarget t;
        t.patient = c.patient;
        t.port = c.port;
        t.q_deg = Deg(found[0].q_rad);
        t.branch = BendingSigns(t.q_deg);
        t.clearance_m = found[0].clearance_m;
        t.path_clearance_m = std::numeric_limits<double>::infinity();
        const auto segment = [&](const std::vector<double>& other_deg, const std::string& name) {
          const double c = SegmentClearance(&world, found[0].q_rad, Rad(other_deg), spec.path_step_deg);
          if (c < t.path_clearance_m) {
            t.path_clearance_m = c;
            t.worst_segment = name;
          }
        };
        for (const CatalogStart& start : catalog.starts) segment(start.q_deg, start.id);
        if (!spec.alignment_deg.empty()) segment(spec.alignment_deg.front(), "alignment");
        if (t.path_clearance_m < spec.path_clearance_m) {
          catalog.dropped.push_back(t);
          continue;
        }
        ++c.branches_kept;
        t.id = c.patient + "/" + c.port + "/" + std::to_string(++k);
        catalog.targets.push_back(t);
      }
      catalog.ports.push_back(c);
    }
  }
  return catalog;
}

namespace {

void Vec3(JsonWriter& j, const Eigen::Vector3d& v) { j.Array(std::vector<double>{v.x(), v.y(), v.z()}); }
void Vec2(JsonWriter& j, const Eigen::Vector2d& v) { j.Array(std::vector<double>{v.x(), v.y()}); }

// One target of the catalog file; a dropped one (kept false) has no id and no clearance of its own.
void WriteTarget(JsonWriter* j, const CatalogTarget& t, bool kept) {
  j->BeginObject();
  if (kept) j->Key("id").String(t.id);
  j->Key("patient").String(t.patient);
  j->Key("port").String(t.port);
  j->Key("branch").String(t.branch);
  j->Key("q_deg").Array(t.q_deg);
  if (kept) j->Key("clearance_m").Number(t.clearance_m);
  j->Key("path_clearance_m").Number(t.path_clearance_m);
  j->Key("worst_segment").String(t.worst_segment);
  j->EndObject();
}

}  // namespace

std::string DesignCatalogJson(const DesignCatalog& c) {
  JsonWriter j(2);
  j.BeginObject();
  j.Key("command").String(c.command);
  j.Key("about").String(
      "The set-up study's design catalog: patients, ports, targets and parked starts "
      "(experiments/setup/design.h; docs/studies.md). Each user draws a patient and K (start, target) "
      "pairs.");
  const DesignSpec& s = c.spec;
  j.Key("rules").BeginObject();
  j.Key("umbilicus_offset_m");
  Vec2(j, s.umbilicus_offset_m);
  j.Key("field_offset_m");
  Vec2(j, s.field_offset_m);
  j.Key("port_tilt_deg").Number(s.port_tilt_deg);
  j.Key("stand_off_m").Number(s.stand_off_m);
  j.Key("torso_object").String(s.torso_object);
  j.Key("min_clearance_m").Number(s.min_clearance_m);
  j.Key("min_bend_deg").Number(s.min_bend_deg);
  j.Key("path_clearance_m").Number(s.path_clearance_m);
  j.Key("path_step_deg").Number(s.path_step_deg);
  j.Key("seed").Int(static_cast<int64_t>(s.seed));
  j.Key("ik_starts").Int(s.ik_starts);
  j.Key("alignment_deg").BeginArray();
  for (const std::vector<double>& q : s.alignment_deg) j.Array(q);
  j.EndArray();
  j.EndObject();
  j.Key("patients").BeginArray();
  for (const DesignPatient& p : c.patients) {
    j.BeginObject();
    j.Key("name").String(p.name);
    j.Key("scene").String(p.scene);
    j.Key("source").String(p.source);
    j.EndObject();
  }
  j.EndArray();
  j.Key("ports").BeginArray();
  for (const CatalogPort& p : c.ports) {
    j.BeginObject();
    j.Key("patient").String(p.patient);
    j.Key("port").String(p.port);
    for (const DesignPort& d : s.ports) {
      if (d.name == p.port) {
        j.Key("offset_m");
        Vec2(j, d.offset_m);
        j.Key("source").String(d.source);
      }
    }
    j.Key("p_W_skin");
    Vec3(j, p.p_W_skin);
    j.Key("p_WT");
    Vec3(j, p.p_WT);
    j.Key("insertion_direction_W");
    Vec3(j, p.insertion_direction_W);
    j.Key("branches_tried").Int(p.branches_tried);
    j.Key("branches_found").Int(p.branches_found);
    j.Key("branches_kept").Int(p.branches_kept);
    j.EndObject();
  }
  j.EndArray();
  j.Key("starts").BeginArray();
  for (const CatalogStart& t : c.starts) {
    j.BeginObject();
    j.Key("id").String(t.id);
    j.Key("q_deg").Array(t.q_deg);
    j.Key("why").String(t.why);
    j.Key("clearance_m").Number(t.clearance_m);
    j.EndObject();
  }
  j.EndArray();
  j.Key("targets").BeginArray();
  for (const CatalogTarget& t : c.targets) WriteTarget(&j, t, true);
  j.EndArray();
  // What the path rule dropped, for the record (not read back).
  j.Key("dropped").BeginArray();
  for (const CatalogTarget& t : c.dropped) WriteTarget(&j, t, false);
  j.EndArray();
  j.EndObject();
  return j.str() + "\n";
}

DesignCatalog ReadDesignFile(const std::string& path) {
  constexpr size_t kMaxItems = 10000, kMaxText = 1024, kJoints = 7;
  const JsonFields f(path);
  const nlohmann::json doc = f.ReadFile(path, 16 << 20, 8);
  const JsonAt root{doc, ""};
  DesignCatalog c;
  c.command = f.String(f.Member(root, "command"), kMaxText);
  const JsonAt rules = f.Member(root, "rules");
  c.spec.min_clearance_m = f.Number(f.Member(rules, "min_clearance_m"), 0, 10);
  c.spec.min_bend_deg = f.Number(f.Member(rules, "min_bend_deg"), 0, 90);
  c.spec.path_clearance_m = f.Number(f.Member(rules, "path_clearance_m"), 0, 10);
  c.spec.port_tilt_deg = f.Number(f.Member(rules, "port_tilt_deg"), 0, 90);
  c.spec.stand_off_m = f.Number(f.Member(rules, "stand_off_m"), 0, 1);
  c.spec.seed = static_cast<std::uint64_t>(f.Integer(f.Member(rules, "seed"), 0, int64_t{1} << 53));
  c.spec.patients.clear();
  c.spec.ports.clear();
  c.spec.starts.clear();
  const JsonAt patients = f.Member(root, "patients");
  for (size_t i = 0, n = f.ArraySize(patients, 100); i < n; ++i) {
    const JsonAt p = f.Element(patients, i);
    c.patients.push_back({f.String(f.Member(p, "name"), 64), f.String(f.Member(p, "scene"), kMaxText),
                          f.String(f.Member(p, "source"), kMaxText)});
  }
  if (c.patients.empty()) f.Fail("patients", "at least one patient");
  const JsonAt ports = f.Member(root, "ports");
  for (size_t i = 0, n = f.ArraySize(ports, kMaxItems); i < n; ++i) {
    const JsonAt p = f.Element(ports, i);
    CatalogPort port;
    port.patient = f.String(f.Member(p, "patient"), 64);
    port.port = f.String(f.Member(p, "port"), 64);
    const std::vector<double> t = f.Numbers(f.Member(p, "p_WT"), 3, -100, 100);
    const std::vector<double> d = f.Numbers(f.Member(p, "insertion_direction_W"), 3, -1, 1);
    port.p_WT = Eigen::Vector3d(t[0], t[1], t[2]);
    port.insertion_direction_W = Eigen::Vector3d(d[0], d[1], d[2]);
    c.ports.push_back(port);
  }
  const JsonAt starts = f.Member(root, "starts");
  for (size_t i = 0, n = f.ArraySize(starts, kMaxItems); i < n; ++i) {
    const JsonAt s = f.Element(starts, i);
    CatalogStart start;
    start.id = f.String(f.Member(s, "id"), 64);
    start.q_deg = f.Numbers(f.Member(s, "q_deg"), kJoints, -360, 360);
    start.why = f.String(f.Member(s, "why"), kMaxText);
    start.clearance_m = f.Number(f.Member(s, "clearance_m"), -10, 100);
    c.starts.push_back(start);
  }
  if (c.starts.empty()) f.Fail("starts", "at least one start");
  const JsonAt targets = f.Member(root, "targets");
  for (size_t i = 0, n = f.ArraySize(targets, kMaxItems); i < n; ++i) {
    const JsonAt s = f.Element(targets, i);
    CatalogTarget t;
    t.id = f.String(f.Member(s, "id"), 256);
    t.patient = f.String(f.Member(s, "patient"), 64);
    t.port = f.String(f.Member(s, "port"), 64);
    t.branch = f.String(f.Member(s, "branch"), 8);
    t.q_deg = f.Numbers(f.Member(s, "q_deg"), kJoints, -360, 360);
    t.clearance_m = f.Number(f.Member(s, "clearance_m"), -10, 100);
    t.path_clearance_m = f.Number(f.Member(s, "path_clearance_m"), -10, 100);
    if (const auto w = f.OptionalMember(s, "worst_segment")) t.worst_segment = f.String(*w, 64);
    if (!c.FindPatient(t.patient)) f.Fail(s.key + ".patient", "one of the catalog's patients");
    c.targets.push_back(t);
  }
  return c;
}

UserDesign DrawUserDesign(const DesignCatalog& catalog, std::uint64_t user_seed, int k,
                          const std::optional<std::string>& patient) {
  if (k < 1) throw std::invalid_argument("design: K must be at least 1");
  if (catalog.patients.empty() || catalog.starts.empty())
    throw std::invalid_argument("design: the catalog has no patients or no starts");
  Random rng(user_seed ^ 0xde5196ULL);
  const auto index = [&rng](size_t n) { return std::min(n - 1, static_cast<size_t>(rng.Uniform() * n)); };
  const DesignPatient* drawn = &catalog.patients[index(catalog.patients.size())];
  if (patient) {
    drawn = catalog.FindPatient(*patient);
    if (!drawn) throw std::invalid_argument("design: no patient named " + *patient + " in the catalog");
  }
  std::vector<const CatalogTarget*> pool;
  for (const CatalogTarget& t : catalog.targets) {
    if (t.patient == drawn->name) pool.push_back(&t);
  }
  if (static_cast<int>(pool.size()) < k) {
    throw std::invalid_argument("design: patient " + drawn->name + " has " + std::to_string(pool.size()) +
                                " targets, fewer than K = " + std::to_string(k));
  }
  UserDesign design;
  design.patient = drawn->name;
  design.scene = drawn->scene;
  for (int i = 0; i < k; ++i) {
    // Partial Fisher-Yates: the i-th target uniform over those not yet drawn.
    std::swap(pool[i], pool[i + index(pool.size() - i)]);
    const CatalogStart& start = catalog.starts[index(catalog.starts.size())];
    design.pairs.push_back({start.id, pool[i]->id, start.q_deg, pool[i]->q_deg});
  }
  return design;
}

UserDesign UserDesignFor(const std::string& design_path, const std::string& scene_path, uint64_t user_seed,
                         int k) {
  const DesignCatalog catalog = ReadDesignFile(design_path);
  std::optional<std::string> patient;
  if (!scene_path.empty()) {
    std::string names;
    for (const DesignPatient& p : catalog.patients) {
      std::error_code ec;
      if (std::filesystem::equivalent(SourceTreePath(p.scene), scene_path, ec)) patient = p.name;
      names += (names.empty() ? "" : ", ") + p.scene;
    }
    if (!patient) {
      throw std::invalid_argument("--scene " + scene_path + " is no patient's of " + design_path + " (" +
                                  names + "); give --plan and --start-deg for another scene");
    }
  }
  return DrawUserDesign(catalog, user_seed, k, patient);
}

namespace {
constexpr int kBendingJoints[] = {1, 3, 5};
constexpr double kStraightDeg = 1.0;
int Sign(double q_deg) { return q_deg > kStraightDeg ? 1 : (q_deg < -kStraightDeg ? -1 : 0); }
}  // namespace

Relation BendingRelation(const std::vector<double>& start_deg, const std::vector<double>& target_deg) {
  if (start_deg.size() < 6 || target_deg.size() < 6)
    throw std::invalid_argument("BendingRelation: joint vectors of at least 6 joints");
  int same = 0, opposite = 0;
  for (int j : kBendingJoints) {
    const int product = Sign(start_deg[j]) * Sign(target_deg[j]);
    same += product > 0;
    opposite += product < 0;
  }
  if (same == 3) return Relation::kSame;
  if (opposite == 3) return Relation::kMirror;
  return Relation::kMixed;
}

const char* RelationName(Relation r) {
  switch (r) {
    case Relation::kSame:
      return "same";
    case Relation::kMirror:
      return "mirror";
    case Relation::kMixed:
      return "mixed";
  }
  return "mixed";
}

std::string BendingSigns(const std::vector<double>& q_deg) {
  std::string s;
  for (int j : kBendingJoints) {
    const int sign = static_cast<size_t>(j) < q_deg.size() ? Sign(q_deg[j]) : 0;
    s += sign > 0 ? '+' : (sign < 0 ? '-' : '0');
  }
  return s;
}

}  // namespace orbed::setup
