#include "sim/robot_model.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include "base/source_paths.h"
#include "base/units.h"
#include "base/utf8.h"

namespace orbed::sim {
namespace {

std::string Fmt(double v, int precision = 3) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(precision);
  os << v;
  return os.str();
}

Eigen::Isometry3d ToIsometry(const urdf::Pose& pose) {
  double x, y, z, w;
  pose.rotation.getQuaternion(x, y, z, w);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  X.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return X;
}

bool FinitePositive(double v) { return std::isfinite(v) && v > 0; }

// urdfdom 3.0.1 links every joint's parent and child with owning pointers before it looks for the
// root, so a joint whose child is its own parent, or a loop of joints, leaves a reference cycle that
// is never freed, whether the parse then fails or not (found by fuzz_urdf). This reads the joints'
// <parent link> and <child link> with the same XML parser (TinyXML) first and returns what is wrong:
// more than kMaxUrdfJoints joints (the model is walked recursively later) or the loop as
// "the joints form a loop ...: 'a' -> 'b' -> 'a'"; "" when neither (or the XML does not parse:
// urdfdom refuses that before it links anything).
constexpr int kMaxUrdfJoints = 1000;

std::string CheckJointGraph(const std::string& urdf_xml) {
  TiXmlDocument doc;
  doc.Parse(urdf_xml.c_str());
  if (doc.Error()) return "";
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) return "";
  std::map<std::string, std::vector<std::string>> children_of;
  int num_joints = 0;
  for (const TiXmlElement* joint = robot->FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    const TiXmlElement* parent = joint->FirstChildElement("parent");
    const TiXmlElement* child = joint->FirstChildElement("child");
    const char* parent_name = parent != nullptr ? parent->Attribute("link") : nullptr;
    const char* child_name = child != nullptr ? child->Attribute("link") : nullptr;
    if (parent_name == nullptr || child_name == nullptr) continue;
    children_of[parent_name].push_back(child_name);
    if (++num_joints > kMaxUrdfJoints) {
      return "more than " + std::to_string(kMaxUrdfJoints) + " joints (a robot has tens)";
    }
  }
  // Depth-first search with an explicit stack (a file may hold a very long chain); a link met
  // again while it is still on the path closes a loop.
  enum class Mark { kOnPath, kDone };
  std::map<std::string, Mark> mark;
  const std::vector<std::string> no_children;
  for (const auto& root : children_of) {
    if (mark.count(root.first) != 0) continue;
    // Each frame: a link on the path and the index of its next child to visit.
    std::vector<std::pair<std::string, size_t>> path{{root.first, 0}};
    mark[root.first] = Mark::kOnPath;
    while (!path.empty()) {
      auto& [link, next] = path.back();
      const auto found = children_of.find(link);
      const std::vector<std::string>& children = found != children_of.end() ? found->second : no_children;
      if (next == children.size()) {
        mark[link] = Mark::kDone;
        path.pop_back();
        continue;
      }
      const std::string child = children[next++];
      const auto seen = mark.find(child);
      if (seen == mark.end()) {
        mark[child] = Mark::kOnPath;
        path.emplace_back(child, 0);
      } else if (seen->second == Mark::kOnPath) {
        std::string loop;
        size_t k = 0;
        while (path[k].first != child) ++k;
        for (; k < path.size(); ++k) loop += "'" + path[k].first + "' -> ";
        return "the joints form a loop (a URDF must be a tree): " + loop + "'" + child + "'";
      }
    }
  }
  return "";
}

}  // namespace

std::vector<CollisionPrimitive> FuseCapsules(const std::vector<CollisionPrimitive>& primitives) {
  using Kind = CollisionPrimitive::Kind;
  const std::vector<CollisionPrimitive>& in = primitives;
  std::vector<bool> used(in.size(), false);
  std::vector<CollisionPrimitive> out;
  for (size_t i = 0; i < in.size(); ++i) {
    if (in[i].kind != Kind::kCylinder) continue;
    const CollisionPrimitive& cylinder = in[i];
    int caps[2] = {-1, -1};
    for (int e = 0; e < 2; ++e) {
      const Eigen::Vector3d p_LE =
          cylinder.X_LG * Eigen::Vector3d(0, 0, (e == 0 ? -0.5 : 0.5) * cylinder.length_m);
      for (size_t j = 0; j < in.size(); ++j) {
        if (used[j] || in[j].kind != Kind::kSphere || static_cast<int>(j) == caps[0]) continue;
        if (std::abs(in[j].radius_m - cylinder.radius_m) <= kCapsuleFuseToleranceM &&
            (in[j].X_LG.translation() - p_LE).norm() <= kCapsuleFuseToleranceM) {
          caps[e] = static_cast<int>(j);
          break;
        }
      }
    }
    if (caps[0] < 0 || caps[1] < 0) continue;
    used[i] = used[caps[0]] = used[caps[1]] = true;
    CollisionPrimitive capsule = cylinder;
    capsule.kind = Kind::kCapsule;
    out.push_back(capsule);
  }
  for (size_t i = 0; i < in.size(); ++i) {
    if (!used[i]) out.push_back(in[i]);
  }
  return out;
}

Eigen::VectorXd DegToRad(const Eigen::VectorXd& q_deg) { return q_deg * kDegToRad; }
Eigen::VectorXd RadToDeg(const Eigen::VectorXd& q_rad) { return q_rad * kRadToDeg; }

RobotModel RobotModel::LoadFlag(const std::string& path) {
  return LoadFile(path.empty() ? SourceTreePath(kDefaultUrdfRelativePath) : path);
}

RobotModel RobotModel::LoadFile(const std::string& path, const std::string& flange_link,
                                const std::string& tool_tip_link) {
  std::ifstream in(path);
  if (!in) {
    throw std::runtime_error(path + ": cannot open the URDF file (check the path; the default is " +
                             kDefaultUrdfRelativePath + " in the source tree)");
  }
  std::stringstream ss;
  ss << in.rdbuf();
  return LoadString(ss.str(), path, flange_link, tool_tip_link);
}

RobotModel RobotModel::LoadString(const std::string& urdf_xml, const std::string& source_name,
                                  const std::string& flange_link, const std::string& tool_tip_link) {
  const std::string src = source_name;
  auto fail = [&src](const std::string& what) -> void { throw std::runtime_error(src + ": " + what); };
  // TinyXML, under urdfdom and CheckJointGraph, reads past the end of text that is not UTF-8.
  const size_t bad_byte = FindInvalidUtf8(urdf_xml);
  if (bad_byte != std::string_view::npos) {
    fail("byte " + std::to_string(bad_byte) + " is not valid UTF-8 text (a URDF is an XML text file)");
  }
  const std::string graph_error = CheckJointGraph(urdf_xml);
  if (!graph_error.empty()) fail(graph_error);
  urdf::ModelInterfaceSharedPtr urdf_model = urdf::parseURDF(urdf_xml);
  if (!urdf_model) {
    fail(
        "urdfdom could not parse this URDF (malformed XML, a missing <robot>, a joint naming an "
        "unknown link, or a loop; `check_urdf` prints the details)");
  }
  urdf::LinkConstSharedPtr root = urdf_model->getRoot();
  if (!root) fail("the URDF has no root link");

  RobotModel model;
  model.source_name_ = source_name;
  std::map<std::string, int> index_of;

  // Depth-first walk from the root, parent before child.
  std::function<void(const urdf::LinkConstSharedPtr&, int)> visit = [&](const urdf::LinkConstSharedPtr& link,
                                                                        int parent) {
    RobotLink out;
    out.name = link->name;
    out.parent = parent;
    if (parent >= 0) {
      const urdf::JointConstSharedPtr joint = link->parent_joint;
      const std::string where = "joint '" + joint->name + "'";
      out.joint_name = joint->name;
      out.X_PJ = ToIsometry(joint->parent_to_joint_origin_transform);
      if (joint->type == urdf::Joint::REVOLUTE) {
        const Eigen::Vector3d axis(joint->axis.x, joint->axis.y, joint->axis.z);
        if (!axis.allFinite() || axis.norm() < 1e-9) fail(where + ": <axis xyz> must be a non-zero vector");
        out.axis_J = axis.normalized();
        if (!joint->limits) fail(where + ": a revolute joint needs <limit lower upper velocity>");
        JointInfo info;
        info.name = joint->name;
        info.lower_rad = joint->limits->lower;
        info.upper_rad = joint->limits->upper;
        info.velocity_rad_per_s = joint->limits->velocity;
        if (!std::isfinite(info.lower_rad) || !std::isfinite(info.upper_rad) ||
            !(info.lower_rad < info.upper_rad)) {
          fail(where + ": <limit lower upper> must be finite with lower < upper (got " + Fmt(info.lower_rad) +
               ", " + Fmt(info.upper_rad) + ")");
        }
        if (!FinitePositive(info.velocity_rad_per_s)) {
          fail(where + ": <limit velocity> must be > 0 rad/s (got " + Fmt(info.velocity_rad_per_s) + ")");
        }
        out.joint_index = static_cast<int>(model.joints_.size());
        info.link = static_cast<int>(model.links_.size());
        model.joints_.push_back(info);
      } else if (joint->type != urdf::Joint::FIXED) {
        fail(where + ": only 'revolute' (with limits) and 'fixed' joints are supported");
      }
    }
    for (const auto& c : link->collision_array) {
      if (!c || !c->geometry) continue;
      const std::string where =
          "link '" + link->name + "' <collision" + (c->name.empty() ? "" : " name='" + c->name + "'") + ">";
      CollisionPrimitive g;
      g.name = c->name;
      g.X_LG = ToIsometry(c->origin);
      switch (c->geometry->type) {
        case urdf::Geometry::SPHERE: {
          const auto& s = static_cast<const urdf::Sphere&>(*c->geometry);
          g.kind = CollisionPrimitive::Kind::kSphere;
          g.radius_m = s.radius;
          if (!FinitePositive(g.radius_m)) fail(where + ": <sphere radius> must be > 0 m");
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto& s = static_cast<const urdf::Cylinder&>(*c->geometry);
          g.kind = CollisionPrimitive::Kind::kCylinder;
          g.radius_m = s.radius;
          g.length_m = s.length;
          if (!FinitePositive(g.radius_m) || !FinitePositive(g.length_m)) {
            fail(where + ": <cylinder radius length> must both be > 0 m");
          }
          break;
        }
        case urdf::Geometry::BOX: {
          const auto& s = static_cast<const urdf::Box&>(*c->geometry);
          g.kind = CollisionPrimitive::Kind::kBox;
          g.size_m = Eigen::Vector3d(s.dim.x, s.dim.y, s.dim.z);
          if (!(g.size_m.array() > 0).all() || !g.size_m.allFinite()) {
            fail(where + ": <box size> must be three lengths > 0 m");
          }
          break;
        }
        default:
          fail(where +
               ": only <sphere>, <cylinder> and <box> collision geometry is supported "
               "(meshes are not; <capsule> is dropped by urdfdom — use a cylinder plus two spheres)");
      }
      out.collision.push_back(g);
    }
    const int me = static_cast<int>(model.links_.size());
    index_of[out.name] = me;
    model.links_.push_back(out);
    for (const auto& child : link->child_links) visit(child, me);
  };
  visit(root, -1);
  if (model.joints_.empty()) fail("the URDF has no revolute joint");

  // Rigid bodies: a link joined to its parent by a fixed joint shares the parent's body.
  for (auto& link : model.links_) {
    if (link.parent >= 0 && link.joint_index < 0) {
      link.body = model.links_[link.parent].body;
    } else {
      link.body = model.num_bodies_++;
    }
    if (link.parent >= 0 && link.joint_index >= 0) {
      model.adjacent_bodies_.emplace_back(model.links_[link.parent].body, link.body);
    }
  }

  auto find = [&](const std::string& name) {
    auto it = index_of.find(name);
    return it == index_of.end() ? -1 : it->second;
  };
  model.flange_link_ = find(flange_link);
  if (model.flange_link_ < 0) {
    fail("no link named '" + flange_link + "' (the flange F); name the flange link or add it");
  }
  model.tool_tip_link_ = find(tool_tip_link);
  if (model.tool_tip_link_ < 0) {
    model.tool_tip_link_ = model.flange_link_;
  } else {
    // The tool tip must be rigidly attached to the flange, displaced along F's z axis.
    const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(model.num_joints());
    const auto X = model.CalcLinkPoses(q0);
    const Eigen::Isometry3d X_FT = X[model.flange_link_].inverse() * X[model.tool_tip_link_];
    if (model.links_[model.tool_tip_link_].body != model.links_[model.flange_link_].body) {
      fail("link '" + tool_tip_link +
           "' (the tool tip T) must be attached to the flange by fixed joints only");
    }
    if ((X_FT.linear() - Eigen::Matrix3d::Identity()).norm() > 1e-9 ||
        X_FT.translation().head<2>().norm() > 1e-9 || X_FT.translation().z() <= 0) {
      fail("link '" + tool_tip_link + "' (the tool tip T) must sit on F's +z axis with F's orientation");
    }
    model.tool_length_m_ = X_FT.translation().z();
    model.tool_link_ = model.links_[model.tool_tip_link_].parent;
  }
  return model;
}

int RobotModel::FindLink(const std::string& name) const {
  for (int i = 0; i < num_links(); ++i) {
    if (links_[i].name == name) return i;
  }
  return -1;
}

void RobotModel::SetToolLength(double length_m) {
  if (!std::isfinite(length_m) || length_m <= 0) {
    throw std::invalid_argument("tool length must be a finite length > 0 m (got " + Fmt(length_m, 6) + ")");
  }
  if (tool_tip_link_ == flange_link_) {
    throw std::invalid_argument(source_name_ + " has no tool tip link, so the tool length cannot be set");
  }
  const double delta = length_m - tool_length_m_;
  // Direction of F's z axis in the tool-tip parent's frame P: X_FP is fixed.
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(num_joints());
  const auto X = CalcLinkPoses(q0);
  const int parent = links_[tool_tip_link_].parent;
  const Eigen::Isometry3d X_FP = X[flange_link_].inverse() * X[parent];
  const Eigen::Vector3d z_F_in_P = X_FP.linear().transpose() * Eigen::Vector3d::UnitZ();
  // The tool cylinder(s) ending at the old tip, on the tool link.
  std::vector<CollisionPrimitive> updated = links_[parent].collision;
  for (auto& g : updated) {
    if (g.kind != CollisionPrimitive::Kind::kCylinder) continue;
    const Eigen::Vector3d axis_P = g.X_LG.linear().col(2);
    if (std::abs(std::abs(axis_P.dot(z_F_in_P)) - 1.0) > 1e-9) continue;
    const Eigen::Vector3d centre_F = X_FP * g.X_LG.translation();
    if (std::abs(centre_F.z() + 0.5 * g.length_m - tool_length_m_) > 1e-6) continue;
    const double new_length = g.length_m + delta;
    if (new_length < 1e-3) {
      throw std::invalid_argument("tool length " + Fmt(length_m) + " m is too short: the tool's '" + g.name +
                                  "' cylinder would vanish (it starts " +
                                  Fmt(centre_F.z() - 0.5 * g.length_m) + " m from the flange)");
    }
    g.length_m = new_length;
    g.X_LG.translation() += 0.5 * delta * z_F_in_P;
  }
  links_[parent].collision = updated;
  links_[tool_tip_link_].X_PJ.translation() += delta * z_F_in_P;
  tool_length_m_ = length_m;
}

bool RobotModel::BodiesAdjacent(int body_a, int body_b) const {
  if (body_a == body_b) return true;
  for (const auto& [a, b] : adjacent_bodies_) {
    if ((a == body_a && b == body_b) || (a == body_b && b == body_a)) return true;
  }
  return false;
}

int RobotModel::BodySeparation(int body_a, int body_b) const {
  // Breadth-first search over the joint graph (a tree of a few bodies).
  std::vector<int> dist(num_bodies_, -1);
  std::vector<int> queue{body_a};
  dist[body_a] = 0;
  for (size_t head = 0; head < queue.size(); ++head) {
    const int u = queue[head];
    if (u == body_b) return dist[u];
    for (const auto& [a, b] : adjacent_bodies_) {
      const int v = a == u ? b : (b == u ? a : -1);
      if (v >= 0 && dist[v] < 0) {
        dist[v] = dist[u] + 1;
        queue.push_back(v);
      }
    }
  }
  return -1;
}

Eigen::VectorXd RobotModel::lower_limits_rad() const {
  Eigen::VectorXd v(num_joints());
  for (int i = 0; i < num_joints(); ++i) v[i] = joints_[i].lower_rad;
  return v;
}
Eigen::VectorXd RobotModel::upper_limits_rad() const {
  Eigen::VectorXd v(num_joints());
  for (int i = 0; i < num_joints(); ++i) v[i] = joints_[i].upper_rad;
  return v;
}
Eigen::VectorXd RobotModel::velocity_limits_rad_per_s() const {
  Eigen::VectorXd v(num_joints());
  for (int i = 0; i < num_joints(); ++i) v[i] = joints_[i].velocity_rad_per_s;
  return v;
}

std::string RobotModel::ValidateJointVector(const Eigen::VectorXd& q_rad, double tolerance_rad) const {
  if (q_rad.size() != num_joints()) {
    return "expected " + std::to_string(num_joints()) + " joint values, got " + std::to_string(q_rad.size());
  }
  for (int i = 0; i < num_joints(); ++i) {
    const JointInfo& j = joints_[i];
    if (!std::isfinite(q_rad[i])) return j.name + " is not a finite number";
    if (q_rad[i] < j.lower_rad - tolerance_rad || q_rad[i] > j.upper_rad + tolerance_rad) {
      return j.name + " = " + Fmt(q_rad[i] * kRadToDeg) + " deg is outside [" +
             Fmt(j.lower_rad * kRadToDeg, 1) + ", " + Fmt(j.upper_rad * kRadToDeg, 1) + "] deg";
    }
  }
  return "";
}

namespace {
// X_RL of `link` from its parent's pose X_RP: CalcLinkPoses and UpdateLinkPosesForJoint share it,
// so both give the same bits.
Eigen::Isometry3d ChildPose(const RobotLink& link, const Eigen::Isometry3d& X_RP,
                            const Eigen::VectorXd& q_rad) {
  Eigen::Isometry3d X = X_RP * link.X_PJ;
  if (link.joint_index >= 0) {
    X.linear() = X.linear() * Eigen::AngleAxisd(q_rad[link.joint_index], link.axis_J).toRotationMatrix();
  }
  return X;
}
}  // namespace

void RobotModel::CalcLinkPoses(const Eigen::VectorXd& q_rad, std::vector<Eigen::Isometry3d>* X_RL) const {
  if (q_rad.size() != num_joints()) {
    throw std::invalid_argument("CalcLinkPoses: expected " + std::to_string(num_joints()) +
                                " joint values, got " + std::to_string(q_rad.size()));
  }
  X_RL->resize(links_.size());
  for (size_t i = 0; i < links_.size(); ++i) {
    if (links_[i].parent < 0) {
      (*X_RL)[i].setIdentity();
      continue;
    }
    (*X_RL)[i] = ChildPose(links_[i], (*X_RL)[links_[i].parent], q_rad);
  }
}

void RobotModel::UpdateLinkPosesForJoint(const Eigen::VectorXd& q_rad, int joint, int last_link,
                                         std::vector<Eigen::Isometry3d>* X_RL) const {
  if (q_rad.size() != num_joints() || joint < 0 || joint >= num_joints() || X_RL->size() != links_.size() ||
      last_link >= num_links()) {
    throw std::invalid_argument(
        "UpdateLinkPosesForJoint: joint, link or vector size does not match the model");
  }
  // A parent comes before its children (LoadFile orders the links so), so the links the joint
  // moves follow its child link, and each one's parent is updated before it.
  const int first = joints_[joint].link;
  for (int i = first; i <= last_link; ++i) {
    int up = i;
    while (up > first) up = links_[up].parent;
    if (up != first) continue;
    (*X_RL)[i] = ChildPose(links_[i], (*X_RL)[links_[i].parent], q_rad);
  }
}

std::vector<Eigen::Isometry3d> RobotModel::CalcLinkPoses(const Eigen::VectorXd& q_rad) const {
  std::vector<Eigen::Isometry3d> X_RL;
  CalcLinkPoses(q_rad, &X_RL);
  return X_RL;
}

Eigen::Isometry3d RobotModel::CalcFlangePose(const Eigen::VectorXd& q_rad) const {
  return CalcLinkPoses(q_rad)[flange_link_];
}

Eigen::Isometry3d RobotModel::CalcToolTipPose(const Eigen::VectorXd& q_rad) const {
  return CalcLinkPoses(q_rad)[tool_tip_link_];
}

Eigen::MatrixXd RobotModel::CalcJacobian(const Eigen::VectorXd& q_rad, int link) const {
  return CalcJacobian(CalcLinkPoses(q_rad), link);
}

Eigen::MatrixXd RobotModel::CalcJacobian(const std::vector<Eigen::Isometry3d>& X_RL, int link) const {
  if (link < 0 || link >= num_links() || static_cast<int>(X_RL.size()) != num_links()) {
    throw std::invalid_argument("CalcJacobian: bad link index or pose vector size");
  }
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, num_joints());
  const Eigen::Vector3d p_RL = X_RL[link].translation();
  for (int i = link; i >= 0; i = links_[i].parent) {
    const RobotLink& l = links_[i];
    if (l.joint_index < 0) continue;
    // The joint frame and the child link frame share origin and axis (the rotation is about axis_J).
    const Eigen::Vector3d w = X_RL[i].linear() * l.axis_J;
    J.block<3, 1>(0, l.joint_index) = w;
    J.block<3, 1>(3, l.joint_index) = w.cross(p_RL - X_RL[i].translation());
  }
  return J;
}

}  // namespace orbed::sim
