#include "sim/robot_tool.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "base/command_line.h"
#include "base/json.h"
#include "base/number_list.h"
#include "base/source_paths.h"
#include "base/units.h"
#include "sim/collision_world.h"
#include "sim/robot_model.h"
#include "sim/scene.h"
#include "sim/trocar_clearance.h"
#include "sim/trocar_ik.h"
#include "sim/trocar_plan.h"

namespace orbed::sim {
namespace {

// A bad argument: reported on one line, exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

Eigen::VectorXd ParseJointList(const std::string& text, int expected) {
  std::vector<double> values;
  try {
    values = ParseNumberList(text, "--q-deg");
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (static_cast<int>(values.size()) != expected) {
    throw UsageError("--q-deg: expected " + std::to_string(expected) +
                     " comma-separated angles in deg, got " + std::to_string(values.size()));
  }
  return Eigen::Map<Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

// The robot from --urdf (default: the shipped model), as it stands in `scene` if one is given.
RobotModel LoadModel(const std::string& urdf_flag, const Scene* scene = nullptr) {
  const std::string path =
      urdf_flag.empty() ? SourceTreePath(RobotModel::kDefaultUrdfRelativePath) : urdf_flag;
  try {
    return scene ? LoadRobotForScene(path, *scene) : RobotModel::LoadFile(path);
  } catch (const std::exception& e) {
    throw UsageError(e.what());
  }
}

Scene LoadScene(const std::string& path) {
  try {
    return LoadSceneFile(path);
  } catch (const std::exception& e) {
    throw UsageError(e.what());
  }
}

Eigen::VectorXd ValidatedQ(const RobotModel& model, const std::string& q_text) {
  const Eigen::VectorXd q = DegToRad(ParseJointList(q_text, model.num_joints()));
  const std::string why = model.ValidateJointVector(q);
  if (!why.empty()) throw UsageError("--q-deg: " + why);
  return q;
}

void WritePose(JsonWriter& j, const Eigen::Isometry3d& X) {
  j.BeginObject();
  const Eigen::Vector3d p = X.translation();
  j.Key("position_m").Array(std::vector<double>{p.x(), p.y(), p.z()});
  j.Key("rotation").BeginArray();
  for (int r = 0; r < 3; ++r) {
    j.Array(std::vector<double>{X.linear()(r, 0), X.linear()(r, 1), X.linear()(r, 2)});
  }
  j.EndArray();
  j.EndObject();
}

void WriteVec(JsonWriter& j, const Eigen::Vector3d& v) { j.Array(std::vector<double>{v.x(), v.y(), v.z()}); }

void WritePair(JsonWriter& j, const PairDistance& p) {
  if (!p.valid()) {
    j.Null();
    return;
  }
  j.BeginObject();
  j.Key("a").String(p.body_a);
  j.Key("b").String(p.body_b);
  j.Key("self").Bool(p.self);
  j.Key("distance_m").Number(p.distance_m);
  j.Key("p_WA");
  WriteVec(j, p.p_WA);
  j.Key("p_WB");
  WriteVec(j, p.p_WB);
  j.EndObject();
}

void WriteCheck(JsonWriter& j, const RobotModel& model, const CollisionWorld& world,
                const CollisionResult& r) {
  j.Key("in_collision").Bool(r.in_collision);
  j.Key("min_distance_m").Number(r.min_distance_m);
  j.Key("closest");
  WritePair(j, r.closest);
  j.Key("closest_self");
  WritePair(j, r.closest_self);
  j.Key("closest_environment");
  WritePair(j, r.closest_environment);
  j.Key("link_clearance_m").BeginObject();
  for (int i = 0; i < model.num_links(); ++i) {
    if (std::isfinite(r.link_clearance_m[i])) j.Key(model.links()[i].name).Number(r.link_clearance_m[i]);
  }
  j.EndObject();
  j.Key("pairs_checked").BeginObject();
  j.Key("self").Int(world.num_self_pairs());
  j.Key("environment").Int(world.num_environment_pairs());
  j.EndObject();
}

int RunFk(const std::string& q_text, const std::string& urdf, std::ostream& out) {
  const RobotModel model = LoadModel(urdf);
  const Eigen::VectorXd q = ValidatedQ(model, q_text);
  const auto X_RL = model.CalcLinkPoses(q);
  JsonWriter j;
  j.BeginObject();
  j.Key("frame").String("R");
  const Eigen::VectorXd q_deg = RadToDeg(q);
  j.Key("q_deg").Array(std::vector<double>(q_deg.data(), q_deg.data() + q_deg.size()));
  j.Key("flange");
  WritePose(j, X_RL[model.flange_link()]);
  j.Key("tool_tip");
  WritePose(j, X_RL[model.tool_tip_link()]);
  j.Key("tool_length_m").Number(model.tool_length_m());
  j.Key("links").BeginObject();
  for (int i = 0; i < model.num_links(); ++i) {
    j.Key(model.links()[i].name);
    WritePose(j, X_RL[i]);
  }
  j.EndObject();
  j.EndObject();
  out << j.str() << "\n";
  return 0;
}

int RunCheck(const std::string& q_text, const std::string& scene_path, const std::string& urdf,
             std::ostream& out) {
  Scene scene;
  const bool has_scene = !scene_path.empty();
  if (has_scene) scene = LoadScene(scene_path);
  const RobotModel model = LoadModel(urdf, has_scene ? &scene : nullptr);
  const Eigen::VectorXd q = ValidatedQ(model, q_text);
  CollisionWorld world(model, has_scene ? &scene : nullptr);
  const CollisionResult r = world.Check(q);
  JsonWriter j;
  j.BeginObject();
  j.Key("frame").String(has_scene ? "W" : "R");
  if (has_scene) {
    j.Key("scene").String(scene_path);
  } else {
    j.Key("scene").Null();
  }
  j.Key("within_limits").Bool(true);
  WriteCheck(j, model, world, r);
  j.EndObject();
  out << j.str() << "\n";
  return 0;
}

int RunIk(const std::string& scene_path, const std::string& urdf, uint64_t seed, int starts,
          std::ostream& out) {
  const Scene scene = LoadScene(scene_path);
  const RobotModel model = LoadModel(urdf, &scene);
  CollisionWorld world(model, &scene);
  const ClearanceFunction clearance = MakeTrocarClearanceFunction(model, scene);
  const TrocarIkTarget target = TrocarTargetInBase(scene);
  TrocarIkOptions options;
  options.seed = seed;
  options.num_seeds = starts;
  const TrocarIkResult ik = SolveTrocarIk(model, target, options, clearance);

  JsonWriter j;
  j.BeginObject();
  j.Key("success").Bool(ik.success);
  j.Key("message").String(ik.message);
  j.Key("scene").String(scene_path);
  if (ik.q_rad.size() > 0) {
    const Eigen::VectorXd q_deg = RadToDeg(ik.q_rad);
    j.Key("q_deg").Array(std::vector<double>(q_deg.data(), q_deg.data() + q_deg.size()));
    j.Key("clearance_m").Number(MakeTrocarArmClearanceFunction(model, scene)(ik.q_rad));
    j.Key("objective").Number(ik.clearance_m);
    j.Key("position_error_m").Number(ik.position_error_m);
    j.Key("angle_error_deg").Number(ik.angle_error_rad * kRadToDeg);
    const Eigen::Isometry3d X_WT = scene.X_WR * model.CalcToolTipPose(ik.q_rad);
    j.Key("p_WT");
    WriteVec(j, X_WT.translation());
    j.Key("tool_axis_W");
    WriteVec(j, X_WT.linear().col(2));
    j.Key("check").BeginObject();
    WriteCheck(j, model, world, world.Check(ik.q_rad));
    j.EndObject();
  } else {
    j.Key("q_deg").Null();
  }
  j.Key("starts").Int(ik.seeds_tried);
  j.Key("starts_converged").Int(ik.seeds_converged);
  j.EndObject();
  out << j.str() << "\n";
  return ik.success ? 0 : 1;
}

// plan: every target's q and what it was checked for; exit 1 (one line on stderr) when the plan
// cannot be made.
int RunPlan(const std::string& scene_path, const std::string& urdf, const TrocarPlanOptions& options,
            std::ostream& out, std::ostream& err) {
  const Scene scene = LoadScene(scene_path);
  const RobotModel model = LoadModel(urdf, &scene);
  std::vector<PlannedTarget> plan;
  try {
    plan = PlanTrocarTargets(model, scene, options);
  } catch (const std::runtime_error& e) {
    err << "orbed-robot: " << e.what() << "\n";
    return 1;
  }
  JsonWriter j;
  j.BeginObject();
  j.Key("scene").String(scene_path);
  j.Key("min_separation_deg").Number(options.min_separation_deg);
  j.Key("min_clearance_m").Number(options.min_clearance_m);
  j.Key("seed").Int(static_cast<int64_t>(options.seed));
  j.Key("targets").BeginArray();
  for (const PlannedTarget& t : plan) {
    const Eigen::VectorXd q_deg = RadToDeg(t.q_rad);
    j.BeginObject();
    j.Key("q_deg").Array(std::vector<double>(q_deg.data(), q_deg.data() + q_deg.size()));
    j.Key("clearance_m").Number(t.clearance_m);
    j.Key("separation_deg").Number(t.separation_deg);
    j.Key("position_error_m").Number(t.position_error_m);
    j.Key("angle_error_deg").Number(t.angle_error_deg);
    j.EndObject();
  }
  j.EndArray();
  j.EndObject();
  out << j.str() << "\n";
  return 0;
}

}  // namespace

int RunRobotTool(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-robot: forward kinematics, collision check and trocar IK of the iiwa 7 model (JSON out)"};
  AddVersionFlag(&app);
  app.require_subcommand(1);
  std::string q_text, urdf, scene_path;
  uint64_t seed = 1;
  int starts = 48;
  auto* fk = app.add_subcommand("fk", "flange, tool tip and link poses in the robot base frame R");
  fk->add_option("--q-deg", q_text, "joint angles q1,...,q7 [deg]")->required();
  fk->add_option("--urdf", urdf, "robot URDF (default: sim/models/iiwa7.urdf of the source tree)");
  auto* check = app.add_subcommand("check", "self and scene collision, minimum distance, closest pair");
  check->add_option("--q-deg", q_text, "joint angles q1,...,q7 [deg]")->required();
  check->add_option("--scene", scene_path, "scene YAML (without it: self-collision only)");
  check->add_option("--urdf", urdf, "robot URDF");
  auto* ik = app.add_subcommand("ik", "collision-free joint vector docking the tool at the scene's trocar");
  ik->add_option("--scene", scene_path, "scene YAML")->required();
  ik->add_option("--urdf", urdf, "robot URDF");
  ik->add_option("--seed", seed, "random seed of the IK starts");
  ik->add_option("--starts", starts, "number of random IK starts")->check(orbed::NumberIn(1, 100000));
  TrocarPlanOptions plan_options;
  auto* plan = app.add_subcommand(
      "plan",
      "distinct collision-free configurations docking the tool at the scene's trocar (the set-up targets)");
  plan->add_option("--scene", scene_path, "scene YAML")->required();
  plan->add_option("--urdf", urdf, "robot URDF");
  plan->add_option("--targets", plan_options.num_targets, "number of targets")
      ->check(orbed::NumberIn(1, 20))
      ->capture_default_str();
  plan->add_option("--min-separation-deg", plan_options.min_separation_deg,
                   "every two targets differ by at least this in some joint [deg]")
      ->check(orbed::NumberIn(0.0, 180.0))
      ->capture_default_str();
  plan->add_option("--min-clearance-m", plan_options.min_clearance_m, "arm clearance of every target [m]")
      ->check(orbed::NonNegativeNumber())
      ->capture_default_str();
  plan->add_option("--seed", plan_options.seed, "random seed of the IK starts")->capture_default_str();
  plan->add_option("--starts", plan_options.starts, "IK starts per target")
      ->check(orbed::NumberIn(1, 1000))
      ->capture_default_str();
  if (const auto code = ParseArguments(&app, argc, argv, out, err)) return *code;
  try {
    if (*fk) return RunFk(q_text, urdf, out);
    if (*check) return RunCheck(q_text, scene_path, urdf, out);
    if (*ik) return RunIk(scene_path, urdf, seed, starts, out);
    if (*plan) return RunPlan(scene_path, urdf, plan_options, out, err);
  } catch (const UsageError& e) {
    err << "orbed-robot: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "orbed-robot: " << e.what() << "\n";
    return 2;
  }
  return 2;
}

}  // namespace orbed::sim
