#include "render/room_mesh.h"

namespace orbed::render {

RoomMesh::RoomMesh(const sim::RobotModel& robot, const SceneGeometry& scene_objects) {
  robot_geometry_.AddRobot(robot, BodyKind::kRealRobot);
  Tessellate(scene_objects, kAllKinds, {}, &scene_mesh_);
  mesh_ = scene_mesh_;
}

void RoomMesh::ClearRobot() { mesh_ = scene_mesh_; }

void RoomMesh::PoseRobot(const Eigen::VectorXd& q_rad, const Eigen::Isometry3d& X_WR) {
  robot_geometry_.PoseRobot(0, q_rad, X_WR);
  mesh_ = scene_mesh_;
  Tessellate(robot_geometry_, kAllKinds, {}, &mesh_);
}

}  // namespace orbed::render
