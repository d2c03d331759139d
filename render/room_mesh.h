#pragma once
/// @file
/// The triangles a camera of the headset sees of the real operating room: the scene's objects,
/// tessellated once, plus the real robot at its joints q and base X_WR, re-tessellated when the
/// robot is posed anew. One definition for every renderer of the real room (the headset's camera
/// frames and reflective captures, the emulated HoloLens 2 depth camera).
///
/// Frames: W world, R real robot base. Units: m, rad.
/// Threading: plain data; one writer (the renderer's thread). The RobotModel passed in must
/// outlive the RoomMesh.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "render/scene_geometry.h"
#include "sim/robot_model.h"

namespace orbed::render {

class RoomMesh {
 public:
  /// `scene_objects` is tessellated now (every body kind it holds) and not kept.
  RoomMesh(const sim::RobotModel& robot, const SceneGeometry& scene_objects);

  /// The scene alone (no robot pose known yet).
  void ClearRobot();
  /// The scene and the real robot at (q, X_WR). Throws std::invalid_argument on a q of the
  /// wrong size (SceneGeometry::PoseRobot).
  void PoseRobot(const Eigen::VectorXd& q_rad, const Eigen::Isometry3d& X_WR);

  /// The triangles as last posed.
  const Mesh& mesh() const { return mesh_; }
  /// The real robot's primitives (handle 0) as last posed, for analytic ray casts.
  const SceneGeometry& robot_geometry() const { return robot_geometry_; }

 private:
  SceneGeometry robot_geometry_;
  Mesh scene_mesh_, mesh_;
};

}  // namespace orbed::render
