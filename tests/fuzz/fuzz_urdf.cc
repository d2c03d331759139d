// libFuzzer: the robot model's URDF loader (urdfdom, then orbed's checks of joints, limits and
// collision shapes).
#include "sim/robot_model.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = orbed::fuzz::AsText(data, size);
  orbed::fuzz::RefuseOrAccept([&] { orbed::sim::RobotModel::LoadString(text, "fuzz.urdf"); });
  return 0;
}
