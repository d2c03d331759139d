#include "render/scene_geometry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "base/units.h"

namespace orbed::render {
namespace {

// Muted OR colours for scene objects (BGR), cycled by object index.
constexpr ColorBgr kScenePalette[] = {
    {165, 170, 175},  // stainless
    {150, 140, 70},   // teal drape
    {110, 160, 200},  // tan
    {200, 150, 120},  // light blue
    {120, 120, 180},  // muted red
    {150, 195, 150},  // pale green
    {95, 130, 160},   // brown-beige
    {190, 175, 170},  // lavender grey
};
constexpr ColorBgr kFloor{88, 90, 92};
constexpr ColorBgr kKukaOrange{20, 105, 235};
constexpr ColorBgr kKukaGrey{205, 200, 198};
constexpr ColorBgr kToolDark{75, 72, 70};
constexpr ColorBgr kHoloCyan{255, 215, 70};
constexpr ColorBgr kHoloTeal{200, 255, 90};
constexpr ColorBgr kHoloTool{255, 170, 150};

Primitive::Shape ShapeOf(sim::CollisionPrimitive::Kind k) {
  switch (k) {
    case sim::CollisionPrimitive::Kind::kSphere:
      return Primitive::Shape::kSphere;
    case sim::CollisionPrimitive::Kind::kCylinder:
      return Primitive::Shape::kCylinder;
    case sim::CollisionPrimitive::Kind::kBox:
      return Primitive::Shape::kBox;
    case sim::CollisionPrimitive::Kind::kCapsule:
      return Primitive::Shape::kCapsule;
  }
  return Primitive::Shape::kSphere;
}

// Appends a triangle with its outward normal computed from the (already world-frame) vertices;
// degenerate triangles are dropped.
void PushTriangle(Mesh* mesh, int a, int b, int c, int body, ColorBgr color) {
  const Eigen::Vector3f& pa = mesh->p_W[a];
  const Eigen::Vector3f n = (mesh->p_W[b] - pa).cross(mesh->p_W[c] - pa);
  const float len = n.norm();
  if (!(len > 1e-12f)) return;
  Mesh::Triangle t;
  t.v = {a, b, c};
  t.body = body;
  t.normal_W = n / len;
  t.color = color;
  mesh->triangles.push_back(t);
}

// A surface of revolution about G's z axis from a profile of (radius, z) points ordered from the top
// (+z) to the bottom; a point with radius 0 is a pole (one vertex). Triangles wind outward.
void Lathe(const std::vector<std::pair<double, double>>& profile, int segments, const Eigen::Isometry3d& X_WG,
           int body, ColorBgr color, Mesh* mesh) {
  std::vector<double> c(segments), s(segments);
  for (int i = 0; i < segments; ++i) {
    c[i] = std::cos(2 * kPi * i / segments);
    s[i] = std::sin(2 * kPi * i / segments);
  }
  // First vertex index of each ring; poles hold a single vertex.
  std::vector<int> first(profile.size());
  std::vector<bool> pole(profile.size());
  for (size_t k = 0; k < profile.size(); ++k) {
    const auto [r, z] = profile[k];
    first[k] = static_cast<int>(mesh->p_W.size());
    pole[k] = r <= 0;
    if (pole[k]) {
      mesh->p_W.push_back((X_WG * Eigen::Vector3d(0, 0, z)).cast<float>());
    } else {
      for (int i = 0; i < segments; ++i)
        mesh->p_W.push_back((X_WG * Eigen::Vector3d(r * c[i], r * s[i], z)).cast<float>());
    }
  }
  for (size_t k = 0; k + 1 < profile.size(); ++k) {
    const int A = first[k], B = first[k + 1];  // upper ring A, lower ring B
    if (pole[k] && pole[k + 1]) continue;
    for (int i = 0; i < segments; ++i) {
      const int j = (i + 1) % segments;
      if (pole[k]) {
        PushTriangle(mesh, A, B + i, B + j, body, color);
      } else if (pole[k + 1]) {
        PushTriangle(mesh, B, A + j, A + i, body, color);
      } else {
        PushTriangle(mesh, B + i, B + j, A + j, body, color);
        PushTriangle(mesh, B + i, A + j, A + i, body, color);
      }
    }
  }
}

void TessellateBox(const Primitive& p, int body, ColorBgr color, Mesh* mesh) {
  const Eigen::Vector3d h = 0.5 * p.size_m;
  const int base = static_cast<int>(mesh->p_W.size());
  // Vertex i has x = ±h.x by bit 0, y by bit 1, z by bit 2.
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p_G((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
    mesh->p_W.push_back((p.X_WG * p_G).cast<float>());
  }
  // Faces as quads wound counter-clockwise seen from outside.
  static constexpr int kQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6},   // -z, +z
                                       {0, 1, 5, 4}, {2, 6, 7, 3},   // -y, +y
                                       {0, 4, 6, 2}, {1, 3, 7, 5}};  // -x, +x
  for (const auto& q : kQuads) {
    PushTriangle(mesh, base + q[0], base + q[1], base + q[2], body, color);
    PushTriangle(mesh, base + q[0], base + q[2], base + q[3], body, color);
  }
}

}  // namespace

void SceneGeometry::AddSceneObjects(const sim::Scene& scene) {
  int n = 0;
  for (const sim::SceneObject& o : scene.objects) {
    Primitive p;
    p.X_WG = o.X_WO;
    p.size_m = o.size_m;
    p.radius_m = o.radius_m;
    p.length_m = o.length_m;
    switch (o.shape) {
      case sim::SceneObject::Shape::kBox:
        p.shape = Primitive::Shape::kBox;
        break;
      case sim::SceneObject::Shape::kCylinder:
        p.shape = Primitive::Shape::kCylinder;
        break;
      case sim::SceneObject::Shape::kSphere:
        p.shape = Primitive::Shape::kSphere;
        break;
    }
    const ColorBgr color =
        o.name == "floor" ? kFloor : kScenePalette[n++ % (sizeof(kScenePalette) / sizeof(ColorBgr))];
    AddBody(o.name, BodyKind::kSceneObject, color, p);
  }
}

int SceneGeometry::AddBody(const std::string& name, BodyKind kind, ColorBgr color,
                           const Primitive& primitive) {
  Body b;
  b.name = name;
  b.kind = kind;
  b.color = color;
  bodies_.push_back(b);
  Primitive p = primitive;
  p.body = static_cast<int>(bodies_.size()) - 1;
  primitives_.push_back(p);
  return p.body;
}

int SceneGeometry::AddRobot(const sim::RobotModel& robot, BodyKind kind) {
  if (kind == BodyKind::kSceneObject) throw std::invalid_argument("AddRobot: kind must be a robot");
  const bool is_virtual = kind == BodyKind::kVirtualRobot;
  RobotEntry entry;
  entry.model = &robot;
  entry.kind = kind;
  const int handle = static_cast<int>(robots_.size());
  int shown = 0;
  for (int l = 0; l < robot.num_links(); ++l) {
    const sim::RobotLink& link = robot.links()[l];
    if (link.collision.empty()) continue;
    Body b;
    b.name = is_virtual ? "virtual/" + link.name : link.name;
    b.kind = kind;
    b.robot = handle;
    b.link = l;
    const bool tool = l == robot.tool_link();
    if (is_virtual) {
      b.color = tool ? kHoloTool : (shown % 2 ? kHoloCyan : kHoloTeal);
    } else {
      b.color = tool ? kToolDark : (shown % 2 ? kKukaOrange : kKukaGrey);
    }
    ++shown;
    bodies_.push_back(b);
    const int body = static_cast<int>(bodies_.size()) - 1;
    // Capsules as one primitive (the collision world's rule): no cylinder end cap peeks through the
    // tessellated spheres, and rays hit the same shape the collision check sees.
    for (const sim::CollisionPrimitive& cp : sim::FuseCapsules(link.collision)) {
      Primitive p;
      p.shape = ShapeOf(cp.kind);
      p.body = body;
      p.size_m = cp.size_m;
      p.radius_m = cp.radius_m;
      p.length_m = cp.length_m;
      entry.primitive_index.push_back(static_cast<int>(primitives_.size()));
      entry.primitive_link.push_back(l);
      entry.X_LG.push_back(cp.X_LG);
      primitives_.push_back(p);
    }
  }
  robots_.push_back(std::move(entry));
  PoseRobot(handle, Eigen::VectorXd::Zero(robot.num_joints()), Eigen::Isometry3d::Identity());
  return handle;
}

void SceneGeometry::PoseRobot(int handle, const Eigen::VectorXd& q_rad, const Eigen::Isometry3d& X_WB) {
  if (handle < 0 || handle >= static_cast<int>(robots_.size()))
    throw std::invalid_argument("PoseRobot: unknown robot handle " + std::to_string(handle));
  RobotEntry& r = robots_[handle];
  r.model->CalcLinkPoses(q_rad, &r.X_BL);  // throws on a wrong size
  for (size_t k = 0; k < r.primitive_index.size(); ++k)
    primitives_[r.primitive_index[k]].X_WG = X_WB * r.X_BL[r.primitive_link[k]] * r.X_LG[k];
}

SceneGeometry SceneGeometry::MakeOperatingRoom(const sim::Scene& scene, const sim::RobotModel& robot,
                                               const Eigen::VectorXd& q_rad, const Eigen::Isometry3d& X_WR,
                                               const Eigen::Isometry3d* X_WV,
                                               const Eigen::VectorXd* q_virtual_rad) {
  SceneGeometry g;
  g.AddSceneObjects(scene);
  g.PoseRobot(g.AddRobot(robot, BodyKind::kRealRobot), q_rad, X_WR);
  if (X_WV != nullptr) {
    g.PoseRobot(g.AddRobot(robot, BodyKind::kVirtualRobot), q_virtual_rad ? *q_virtual_rad : q_rad, *X_WV);
  }
  return g;
}

int SceneGeometry::FindBody(const std::string& name) const {
  for (size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].name == name) return static_cast<int>(i);
  return -1;
}

void TessellatePrimitive(const Primitive& p, int body, ColorBgr color, const TessellationOptions& options,
                         Mesh* mesh) {
  const int seg = std::max(3, options.cylinder_segments);
  const int sseg = std::max(3, options.sphere_segments);
  const int rings = std::max(2, options.sphere_rings);
  std::vector<std::pair<double, double>> profile;
  switch (p.shape) {
    case Primitive::Shape::kBox:
      TessellateBox(p, body, color, mesh);
      return;
    case Primitive::Shape::kCylinder: {
      const double h = 0.5 * p.length_m;
      profile = {{0, h}, {p.radius_m, h}, {p.radius_m, -h}, {0, -h}};
      Lathe(profile, seg, p.X_WG, body, color, mesh);
      return;
    }
    case Primitive::Shape::kSphere:
      for (int k = 0; k <= rings; ++k) {
        const double phi = kPi * k / rings;
        profile.emplace_back(k == 0 || k == rings ? 0.0 : p.radius_m * std::sin(phi),
                             p.radius_m * std::cos(phi));
      }
      Lathe(profile, sseg, p.X_WG, body, color, mesh);
      return;
    case Primitive::Shape::kCapsule: {
      const int half = std::max(2, rings / 2);
      const double h = 0.5 * p.length_m;
      for (int k = 0; k <= half; ++k) {  // top cap, pole to equator
        const double phi = 0.5 * kPi * k / half;
        profile.emplace_back(k == 0 ? 0.0 : p.radius_m * std::sin(phi), h + p.radius_m * std::cos(phi));
      }
      for (int k = 0; k <= half; ++k) {  // bottom cap, equator to pole
        const double phi = 0.5 * kPi + 0.5 * kPi * k / half;
        profile.emplace_back(k == half ? 0.0 : p.radius_m * std::sin(phi), -h + p.radius_m * std::cos(phi));
      }
      Lathe(profile, std::max(seg, sseg), p.X_WG, body, color, mesh);
      return;
    }
  }
}

void Tessellate(const SceneGeometry& geometry, KindMask kinds, const TessellationOptions& options,
                Mesh* mesh) {
  for (const Primitive& p : geometry.primitives()) {
    const Body& b = geometry.bodies()[p.body];
    if (!(kinds & KindBit(b.kind))) continue;
    TessellatePrimitive(p, p.body, b.color, options, mesh);
  }
}

}  // namespace orbed::render
