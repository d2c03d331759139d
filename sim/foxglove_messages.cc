#include "sim/foxglove_messages.h"

#include "base/base64.h"
#include "base/format.h"
#include "lcmtypes/contract/requests.h"
#include "sim/guidance_messages.h"

namespace orbed::foxglove {
namespace {

using json = nlohmann::json;

json Time(int64_t utime) { return {{"sec", utime / 1000000}, {"nsec", (utime % 1000000) * 1000}}; }

json Vector3(const Eigen::Vector3d& v) { return {{"x", v.x()}, {"y", v.y()}, {"z", v.z()}}; }

json Quaternion(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return {{"x", q.x()}, {"y", q.y()}, {"z", q.z()}, {"w", q.w()}};
}

json Pose(const Eigen::Isometry3d& X) {
  return {{"position", Vector3(X.translation())}, {"orientation", Quaternion(X.linear())}};
}

json Color(double r, double g, double b, double a) { return {{"r", r}, {"g", g}, {"b", b}, {"a", a}}; }

// JSON Schema pieces (the shapes of Foxglove's schemas, written out here).
json Number() { return {{"type", "number"}}; }
json Integer() { return {{"type", "integer"}}; }
json Boolean() { return {{"type", "boolean"}}; }
json Text() { return {{"type", "string"}}; }
json Object(const json& properties) { return {{"type", "object"}, {"properties", properties}}; }
json ArrayOf(const json& items) { return {{"type", "array"}, {"items", items}}; }
json TimeSchema() { return Object({{"sec", Integer()}, {"nsec", Integer()}}); }
json Vector3Schema() { return Object({{"x", Number()}, {"y", Number()}, {"z", Number()}}); }
json QuaternionSchema() {
  return Object({{"x", Number()}, {"y", Number()}, {"z", Number()}, {"w", Number()}});
}
json PoseSchema() { return Object({{"position", Vector3Schema()}, {"orientation", QuaternionSchema()}}); }
json ColorSchema() { return Object({{"r", Number()}, {"g", Number()}, {"b", Number()}, {"a", Number()}}); }

json FrameTransformsSchema() {
  return Object({{"transforms", ArrayOf(Object({{"timestamp", TimeSchema()},
                                                {"parent_frame_id", Text()},
                                                {"child_frame_id", Text()},
                                                {"translation", Vector3Schema()},
                                                {"rotation", QuaternionSchema()}}))}});
}

json SceneUpdateSchema() {
  const json shape = Object({{"pose", PoseSchema()}, {"size", Vector3Schema()}, {"color", ColorSchema()}});
  const json cylinder = Object({{"pose", PoseSchema()},
                                {"size", Vector3Schema()},
                                {"bottom_scale", Number()},
                                {"top_scale", Number()},
                                {"color", ColorSchema()}});
  const json deletion = Object({{"timestamp", TimeSchema()}, {"type", Integer()}, {"id", Text()}});
  return Object({{"deletions", ArrayOf(deletion)},
                 {"entities", ArrayOf(Object({{"timestamp", TimeSchema()},
                                              {"frame_id", Text()},
                                              {"id", Text()},
                                              {"lifetime", TimeSchema()},
                                              {"frame_locked", Boolean()},
                                              {"cubes", ArrayOf(shape)},
                                              {"spheres", ArrayOf(shape)},
                                              {"cylinders", ArrayOf(cylinder)}}))}});
}

json CompressedImageSchema() {
  return Object({{"timestamp", TimeSchema()},
                 {"frame_id", Text()},
                 {"data", {{"type", "string"}, {"contentEncoding", "base64"}}},
                 {"format", Text()}});
}

// The primitives of one collision shape, in its parent frame, into `entity`.
void AddPrimitive(const sim::CollisionPrimitive& p, const json& color, json* entity) {
  using Kind = sim::CollisionPrimitive::Kind;
  const double d = 2 * p.radius_m;
  switch (p.kind) {
    case Kind::kSphere:
      (*entity)["spheres"].push_back(
          {{"pose", Pose(p.X_LG)}, {"size", Vector3({d, d, d})}, {"color", color}});
      break;
    case Kind::kBox:
      (*entity)["cubes"].push_back({{"pose", Pose(p.X_LG)}, {"size", Vector3(p.size_m)}, {"color", color}});
      break;
    case Kind::kCylinder:
    case Kind::kCapsule:
      (*entity)["cylinders"].push_back({{"pose", Pose(p.X_LG)},
                                        {"size", Vector3({d, d, p.length_m})},
                                        {"bottom_scale", 1.0},
                                        {"top_scale", 1.0},
                                        {"color", color}});
      if (p.kind == Kind::kCapsule) {
        for (double z : {-0.5 * p.length_m, 0.5 * p.length_m}) {
          Eigen::Isometry3d X = p.X_LG;
          X.translation() += p.X_LG.linear() * Eigen::Vector3d(0, 0, z);
          (*entity)["spheres"].push_back({{"pose", Pose(X)}, {"size", Vector3({d, d, d})}, {"color", color}});
        }
      }
      break;
  }
}

json Entity(const std::string& frame_id, const std::string& id, int64_t utime) {
  return {{"timestamp", Time(utime)},   {"frame_id", frame_id},   {"id", id},
          {"lifetime", Time(0)},        {"frame_locked", true},   {"metadata", json::array()},
          {"arrows", json::array()},    {"cubes", json::array()}, {"spheres", json::array()},
          {"cylinders", json::array()}, {"lines", json::array()}, {"triangles", json::array()},
          {"texts", json::array()},     {"models", json::array()}};
}

json RegistrationSchema() {
  return Object({{"utime", Integer()},
                 {"session_id", Text()},
                 {"valid", Boolean()},
                 {"num_used", Integer()},
                 {"X_WV_mean", PoseSchema()}});
}

json GuidanceSchema() {
  return Object({{"utime", Integer()},
                 {"mode", Text()},
                 {"error_deg", ArrayOf(Number())},
                 {"next_joint", Integer()},
                 {"done", Boolean()}});
}

}  // namespace

const std::vector<ChannelSpec>& Channels() {
  static const std::vector<ChannelSpec> channels = {
      {kTf, "/tf", "foxglove.FrameTransforms", FrameTransformsSchema()},
      {kScene, "/scene", "foxglove.SceneUpdate", SceneUpdateSchema()},
      {kCamera, "/hmd/camera", "foxglove.CompressedImage", CompressedImageSchema()},
      {kReflective, "/reflective", "foxglove.CompressedImage", CompressedImageSchema()},
      {kRegistration, "/registration", "orbed.Registration", RegistrationSchema()},
      {kGuidance, "/guidance", "orbed.Guidance", GuidanceSchema()},
      {kFixedView, "/fixed_view", "foxglove.CompressedImage", CompressedImageSchema()}};
  return channels;
}

std::vector<Frame> RobotFrames(const sim::RobotModel& model, const Eigen::Isometry3d& X_WR,
                               const Eigen::VectorXd& q, const std::optional<Eigen::Isometry3d>& X_WV,
                               const Eigen::VectorXd& q_virtual) {
  std::vector<Frame> frames = {{"W", "R", X_WR}};
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q);
  for (int i = 0; i < model.num_links(); ++i) frames.push_back({"R", model.links()[i].name, X_RL[i]});
  if (X_WV) {
    frames.push_back({"W", "V", *X_WV});
    const std::vector<Eigen::Isometry3d> X_VL = model.CalcLinkPoses(q_virtual);
    for (int i = 0; i < model.num_links(); ++i)
      frames.push_back({"V", "virtual/" + model.links()[i].name, X_VL[i]});
  }
  return frames;
}

json FrameTransforms(const std::vector<Frame>& frames, int64_t utime) {
  json transforms = json::array();
  for (const Frame& f : frames) {
    transforms.push_back({{"timestamp", Time(utime)},
                          {"parent_frame_id", f.parent},
                          {"child_frame_id", f.child},
                          {"translation", Vector3(f.X_PC.translation())},
                          {"rotation", Quaternion(f.X_PC.linear())}});
  }
  return {{"transforms", transforms}};
}

json SceneUpdate(const sim::RobotModel& model, const sim::Scene* scene, bool with_virtual, int64_t utime) {
  json entities = json::array();
  if (scene) {
    const json grey_blue = Color(0.55, 0.6, 0.7, 1.0);
    for (const sim::SceneObject& o : scene->objects) {
      json e = Entity("W", "scene/" + o.name, utime);
      const double d = 2 * o.radius_m;
      switch (o.shape) {
        case sim::SceneObject::Shape::kBox:
          e["cubes"].push_back({{"pose", Pose(o.X_WO)}, {"size", Vector3(o.size_m)}, {"color", grey_blue}});
          break;
        case sim::SceneObject::Shape::kSphere:
          e["spheres"].push_back(
              {{"pose", Pose(o.X_WO)}, {"size", Vector3({d, d, d})}, {"color", grey_blue}});
          break;
        case sim::SceneObject::Shape::kCylinder:
          e["cylinders"].push_back({{"pose", Pose(o.X_WO)},
                                    {"size", Vector3({d, d, o.length_m})},
                                    {"bottom_scale", 1.0},
                                    {"top_scale", 1.0},
                                    {"color", grey_blue}});
          break;
      }
      entities.push_back(e);
    }
  }
  for (int virtual_robot = 0; virtual_robot < (with_virtual ? 2 : 1); ++virtual_robot) {
    const json color = virtual_robot ? Color(0.2, 0.9, 0.3, 0.4) : Color(0.75, 0.75, 0.75, 1.0);
    for (const sim::RobotLink& link : model.links()) {
      if (link.collision.empty()) continue;
      const std::string frame = (virtual_robot ? "virtual/" : "") + link.name;
      json e = Entity(frame, (virtual_robot ? "virtual_robot/" : "robot/") + link.name, utime);
      for (const sim::CollisionPrimitive& p : link.collision) AddPrimitive(p, color, &e);
      entities.push_back(e);
    }
  }
  return {{"deletions", json::array()}, {"entities", entities}};
}

json CompressedImage(const std::vector<uint8_t>& encoded, const std::string& format,
                     const std::string& frame_id, int64_t utime) {
  return {{"timestamp", Time(utime)}, {"frame_id", frame_id}, {"data", Base64(encoded)}, {"format", format}};
}

std::string ImageProblem(const orbed::image_t& img) {
  std::string problem = CheckImage(img);
  if (problem.empty() && img.pixel_format != orbed::image_t::FORMAT_JPEG) problem = "image: not JPEG";
  return problem;
}

json Registration(const orbed::registration_t& msg, const Eigen::Isometry3d& X_WV) {
  return {{"utime", msg.utime},
          {"session_id", EscapeText(msg.session_id)},
          {"valid", true},
          {"num_used", msg.num_used},
          {"X_WV_mean", Pose(X_WV)}};
}

json Guidance(const orbed::guidance_t& msg) {
  return {{"utime", msg.utime},
          {"mode", guidance::GuidanceModeName(msg.mode)},
          {"error_deg", msg.error_deg},
          {"next_joint", msg.next_joint},
          {"done", static_cast<bool>(msg.done)}};
}

}  // namespace orbed::foxglove
