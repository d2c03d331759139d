#include "procs/drake_viewer/drake_viewer.h"

#include <array>
#include <vector>

namespace orbed::viewer {
namespace {

using Color = std::array<float, 4>;
constexpr Color kRealColor = {0.75f, 0.75f, 0.78f, 1.0f};
constexpr Color kVirtualColor = {0.2f, 0.85f, 0.35f, 0.45f};
constexpr Color kSceneColor = {0.55f, 0.6f, 0.7f, 1.0f};

void SetPose(const Eigen::Isometry3d& X, float position[3], float quaternion[4]) {
  const Eigen::Quaterniond q(X.linear());
  for (int i = 0; i < 3; ++i) position[i] = static_cast<float>(X.translation()[i]);
  quaternion[0] = static_cast<float>(q.w());
  quaternion[1] = static_cast<float>(q.x());
  quaternion[2] = static_cast<float>(q.y());
  quaternion[3] = static_cast<float>(q.z());
}

orbed::viewer_geometry_data_t Geometry(int8_t type, const Eigen::Isometry3d& X_LG, const Color& color,
                                       std::vector<float> sizes) {
  orbed::viewer_geometry_data_t g{};
  g.type = type;
  SetPose(X_LG, g.position, g.quaternion);
  for (int i = 0; i < 4; ++i) g.color[i] = color[i];
  g.num_float_data = static_cast<int32_t>(sizes.size());
  g.float_data = std::move(sizes);
  return g;
}

orbed::viewer_geometry_data_t FromPrimitive(const sim::CollisionPrimitive& p, const Color& color) {
  using Kind = sim::CollisionPrimitive::Kind;
  const float r = static_cast<float>(p.radius_m), l = static_cast<float>(p.length_m);
  switch (p.kind) {
    case Kind::kSphere:
      return Geometry(orbed::viewer_geometry_data_t::SPHERE, p.X_LG, color, {r});
    case Kind::kCylinder:
      return Geometry(orbed::viewer_geometry_data_t::CYLINDER, p.X_LG, color, {r, l});
    case Kind::kCapsule:
      return Geometry(orbed::viewer_geometry_data_t::CAPSULE, p.X_LG, color, {r, l});
    case Kind::kBox:
      break;
  }
  return Geometry(
      orbed::viewer_geometry_data_t::BOX, p.X_LG, color,
      {static_cast<float>(p.size_m.x()), static_cast<float>(p.size_m.y()), static_cast<float>(p.size_m.z())});
}

orbed::viewer_geometry_data_t FromObject(const sim::SceneObject& o) {
  using Shape = sim::SceneObject::Shape;
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  switch (o.shape) {
    case Shape::kSphere:
      return Geometry(orbed::viewer_geometry_data_t::SPHERE, I, kSceneColor,
                      {static_cast<float>(o.radius_m)});
    case Shape::kCylinder:
      return Geometry(orbed::viewer_geometry_data_t::CYLINDER, I, kSceneColor,
                      {static_cast<float>(o.radius_m), static_cast<float>(o.length_m)});
    case Shape::kBox:
      break;
  }
  return Geometry(
      orbed::viewer_geometry_data_t::BOX, I, kSceneColor,
      {static_cast<float>(o.size_m.x()), static_cast<float>(o.size_m.y()), static_cast<float>(o.size_m.z())});
}

void AddDrawn(const std::string& name, int32_t robot, const Eigen::Isometry3d& X_WL,
              orbed::viewer_draw_t* draw) {
  draw->link_name.push_back(name);
  draw->robot_num.push_back(robot);
  std::vector<float> p(3), q(4);
  SetPose(X_WL, p.data(), q.data());
  draw->position.push_back(p);
  draw->quaternion.push_back(q);
}

}  // namespace

orbed::viewer_load_robot_t MakeLoadRobot(const sim::RobotModel& model, const sim::Scene* scene) {
  orbed::viewer_load_robot_t load{};
  for (int32_t robot : {kRealRobot, kVirtualRobot}) {
    for (const sim::RobotLink& link : model.links()) {
      orbed::viewer_link_data_t data{};
      data.name = link.name;
      data.robot_num = robot;
      for (const sim::CollisionPrimitive& p : link.collision) {
        data.geom.push_back(FromPrimitive(p, robot == kRealRobot ? kRealColor : kVirtualColor));
      }
      data.num_geom = static_cast<int32_t>(data.geom.size());
      load.link.push_back(std::move(data));
    }
  }
  if (scene) {
    for (const sim::SceneObject& o : scene->objects) {
      orbed::viewer_link_data_t data{};
      data.name = o.name;
      data.robot_num = kScene;
      data.geom.push_back(FromObject(o));
      data.num_geom = 1;
      load.link.push_back(std::move(data));
    }
  }
  load.num_links = static_cast<int32_t>(load.link.size());
  return load;
}

orbed::viewer_draw_t MakeDraw(const sim::RobotModel& model, const sim::Scene* scene,
                              const Eigen::Isometry3d& X_WR, const Eigen::VectorXd& q_real,
                              const std::optional<Eigen::Isometry3d>& X_WV, const Eigen::VectorXd& q_virtual,
                              int64_t utime) {
  orbed::viewer_draw_t draw{};
  draw.timestamp = utime / 1000;
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q_real);
  const std::vector<Eigen::Isometry3d> X_VL = X_WV ? model.CalcLinkPoses(q_virtual) : X_RL;
  for (int i = 0; i < model.num_links(); ++i)
    AddDrawn(model.links()[i].name, kRealRobot, X_WR * X_RL[i], &draw);
  for (int i = 0; i < model.num_links(); ++i) {
    AddDrawn(model.links()[i].name, kVirtualRobot, (X_WV ? *X_WV : X_WR) * X_VL[i], &draw);
  }
  if (scene) {
    for (const sim::SceneObject& o : scene->objects) AddDrawn(o.name, kScene, o.X_WO, &draw);
  }
  draw.num_links = static_cast<int32_t>(draw.link_name.size());
  return draw;
}

}  // namespace orbed::viewer
