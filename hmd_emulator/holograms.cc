#include "hmd_emulator/holograms.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "base/units.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::hmd {
namespace {

using M = orbed::hologram_scene_t;

// A flat rectangle through G's origin: corners `a` ± `u` ± `v`, facing u × v.
void Rectangle(const Eigen::Vector3d& u, const Eigen::Vector3d& v, render::Mesh* mesh) {
  const int base = static_cast<int>(mesh->p_W.size());
  for (const auto& [su, sv] : {std::pair{-1, -1}, std::pair{1, -1}, std::pair{1, 1}, std::pair{-1, 1}})
    mesh->p_W.push_back((su * u + sv * v).cast<float>());
  for (const std::array<int, 3>& t : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
    render::Mesh::Triangle tri;
    tri.v = {base + t[0], base + t[1], base + t[2]};
    tri.normal_W = u.cross(v).normalized().cast<float>();  // set again once posed
    mesh->triangles.push_back(tri);
  }
}

// Unity's primitive of `kind` in G at scale 1 (vertices in G; normals and colours set later).
render::Mesh UnitShape(std::int8_t kind, const render::TessellationOptions& options) {
  render::Mesh mesh;
  render::Primitive p;
  // Cylinder and capsule: render/'s are along z, Unity's along y (z_G turned onto y_G about x_G).
  const Eigen::Isometry3d X_along_y(Eigen::AngleAxisd(-0.5 * kPi, Eigen::Vector3d::UnitX()));
  switch (kind) {
    case M::KIND_CUBE:
      p.shape = render::Primitive::Shape::kBox;
      p.size_m = Eigen::Vector3d::Ones();
      break;
    case M::KIND_SPHERE:
      p.shape = render::Primitive::Shape::kSphere;
      p.radius_m = 0.5;
      break;
    case M::KIND_CYLINDER:
      p.shape = render::Primitive::Shape::kCylinder;
      p.radius_m = 0.5;
      p.length_m = 2.0;
      p.X_WG = X_along_y;
      break;
    case M::KIND_CAPSULE:
      p.shape = render::Primitive::Shape::kCapsule;
      p.radius_m = 0.5;
      p.length_m = 1.0;
      p.X_WG = X_along_y;
      break;
    case M::KIND_PLANE:
      Rectangle(Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(5, 0, 0), &mesh);  // z × x = +y
      return mesh;
    case M::KIND_QUAD:
      Rectangle(Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(0, 0.5, 0), &mesh);  // x × y = +z
      return mesh;
    default:
      return mesh;  // text: nothing to draw
  }
  render::TessellatePrimitive(p, 0, {}, options, &mesh);
  return mesh;
}

std::uint8_t Channel(float c) {
  return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(c, 0.0f, 1.0f)));
}

}  // namespace

void TessellateHolograms(const orbed::hologram_scene_t& msg, const render::TessellationOptions& options,
                         render::Mesh* mesh) {
  for (int i = 0; i < msg.num_holograms; ++i) {
    if (!msg.active[i]) continue;
    const render::Mesh unit = UnitShape(msg.kind[i], options);
    if (unit.triangles.empty()) continue;
    const Eigen::Vector3d scale(msg.scale[i][0], msg.scale[i][1], msg.scale[i][2]);
    const Eigen::Isometry3d X_WG = FromPose(msg.X_WG[i]);
    const bool mirrored = scale.prod() < 0;
    const render::ColorBgr color{Channel(msg.rgba[i][2]), Channel(msg.rgba[i][1]), Channel(msg.rgba[i][0])};
    const int base = static_cast<int>(mesh->p_W.size());
    for (const Eigen::Vector3f& p_G : unit.p_W)
      mesh->p_W.push_back((X_WG * scale.cwiseProduct(p_G.cast<double>())).cast<float>());
    for (const render::Mesh::Triangle& t : unit.triangles) {
      render::Mesh::Triangle tri;
      tri.v = {base + t.v[0], base + (mirrored ? t.v[2] : t.v[1]), base + (mirrored ? t.v[1] : t.v[2])};
      const Eigen::Vector3f& a = mesh->p_W[tri.v[0]];
      const Eigen::Vector3f n = (mesh->p_W[tri.v[1]] - a).cross(mesh->p_W[tri.v[2]] - a);
      if (!(n.norm() > 1e-12f)) continue;
      tri.normal_W = n.normalized();
      tri.body = kHologramBodyBase + i;
      tri.color = color;
      mesh->triangles.push_back(tri);
    }
  }
}

}  // namespace orbed::hmd
