#pragma once
/// @file
/// What the assistant's three test files share (tests only): the shipped iiwa model, a person who
/// sees almost perfectly and whose hand and pace are exact, and a GUIDANCE message for a target
/// (joints alternating twist / revolve, as the iiwa's are; nothing reached yet).

#include <cstdint>
#include <vector>

#include <orbed/guidance_t.hpp>

#include "base/source_paths.h"
#include "procs/assistant/assistant.h"
#include "sim/robot_model.h"

namespace orbed::assistant::test {

inline sim::RobotModel Model() {
  return sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
}

/// A person who sees almost perfectly, whose hand is exact and whose pace is the model's.
inline AssistantConfig Perfect() {
  AssistantConfig c;
  c.user_scale_log_sigma = 0;
  c.lateral_noise_arcmin = 1e-3;
  c.depth_noise_fraction_std = 1e-5;
  c.placement_noise_deg = 0;
  c.rotation_error_base_deg = 0;
  c.rotation_error_per_deg = 0;
  c.display_noise_arcmin = 1e-3;
  c.display_depth_fraction_std = 1e-5;
  c.picture_scale_log_sigma = 0;
  c.picture_noise_arcmin = 1e-3;
  c.picture_depth_fraction_std = 1e-5;
  c.pace_log_sigma = 0;
  return c;
}

/// GUIDANCE in `mode` towards `q_target` [rad], the first `num_joints` of it.
inline orbed::guidance_t Guidance(int8_t mode, const std::vector<double>& q_target, int num_joints) {
  orbed::guidance_t g{};
  g.mode = mode;
  g.num_joints = num_joints;
  for (int i = 0; i < num_joints; ++i) {
    g.target_position.push_back(q_target[i]);
    g.current_position.push_back(0);
    g.error_deg.push_back(0);
    g.joint_kind.push_back(
        int8_t{i % 2 == 0 ? orbed::guidance_t::JOINT_TWIST : orbed::guidance_t::JOINT_REVOLVE});
  }
  g.next_joint = 0;
  return g;
}

}  // namespace orbed::assistant::test
