// The set-up messages' checks (sim/guidance_messages.h) on the shipped iiwa 7: each field out of
// its range is named; a valid message passes.
#include "sim/guidance_messages.h"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "base/source_paths.h"

namespace orbed::guidance {
namespace {

// The set-up study's two messages: each field out of its range is named.
TEST(SetupMessages, ChecksNameTheField) {
  const sim::RobotModel model =
      sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
  orbed::setup_task_t task{};
  task.request_id = 7;
  task.task_id = "u1-ar-1";
  task.mode = orbed::guidance_t::MODE_AR;
  task.num_joints = 7;
  task.target_position.assign(7, 0.1);
  EXPECT_EQ(CheckSetupTask(task, model, 0.0), "");
  auto bad = [&](auto mutate, const std::string& field) {
    orbed::setup_task_t t = task;
    mutate(t);
    const std::string reason = CheckSetupTask(t, model, 0.0);
    EXPECT_NE(reason.find(field), std::string::npos) << reason;
  };
  bad([](orbed::setup_task_t& t) { t.request_id = 0; }, "request_id");
  bad([](orbed::setup_task_t& t) { t.task_id = ""; }, "task_id");
  bad([](orbed::setup_task_t& t) { t.task_id = std::string(257, 'x'); }, "task_id");
  bad([](orbed::setup_task_t& t) { t.mode = 3; }, "mode");
  bad([](orbed::setup_task_t& t) { t.target_position[1] = 2.2; }, "iiwa_joint_2");  // 126 deg > 120
  bad([](orbed::setup_task_t& t) { t.target_position[3] = std::nan(""); }, "target_position");

  orbed::setup_result_t result{};
  result.request_id = 7;
  result.task_id = "u1-ar-1";
  result.num_joints = 7;
  result.reached_position.assign(7, 0.0);
  result.ranges.assign(7, 1);
  result.execution_s = 80;
  result.person_scale = 1.2;
  EXPECT_EQ(CheckSetupResult(result, model, 0.0), "");
  result.ranges[2] = -1;
  EXPECT_NE(CheckSetupResult(result, model, 0.0).find("ranges"), std::string::npos);
  result.ranges[2] = 1;
  result.execution_s = std::numeric_limits<double>::infinity();
  EXPECT_NE(CheckSetupResult(result, model, 0.0).find("execution_s"), std::string::npos);
}

}  // namespace
}  // namespace orbed::guidance
