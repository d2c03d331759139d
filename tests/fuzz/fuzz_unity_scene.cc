// libFuzzer: the hl2ss message queue's remote Unity scene (procs/hl2ss/unity_scene.h), fed a
// client's bytes in three pieces through one session, then a disconnect and a second session.
// Whatever the bytes: one 4-byte answer per command, never more objects than the cap, every
// object's pose finite and rigid, and the HOLOGRAMS message of the scene passes its contract check.
#include <cstdlib>
#include <vector>

#include "lcmtypes/contract/holograms.h"
#include "procs/hl2ss/unity_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using orbed::hl2ss::UmqSession;
  orbed::hl2ss::UnitySceneLimits limits;
  limits.max_objects = 16;          // reachable by a fuzzer
  limits.max_command_bytes = 4096;  // the size cap too
  orbed::hl2ss::UnityScene scene(limits);
  const size_t a = size > 0 ? data[0] % (size + 1) : 0;
  const size_t b = size > 1 ? a + data[1] % (size - a + 1) : a;
  const std::pair<size_t, size_t> pieces[] = {{0, a}, {a, b - a}, {b, size - b}};
  for (int round = 0; round < 2; ++round) {
    UmqSession session(&scene);
    std::vector<uint8_t> reply;
    for (const auto& [from, length] : pieces) {
      if (!session.Consume(data + from, length, &reply)) break;
    }
    if (reply.size() != 4 * static_cast<size_t>(session.commands())) std::abort();
    session.TakeRefusals();
    session.OnDisconnect();
  }
  if (static_cast<int>(scene.objects().size()) > limits.max_objects) std::abort();
  for (const auto& [key, object] : scene.objects()) {
    const Eigen::Matrix3d R = object.X_WG.linear();
    if (key == 0 || !object.X_WG.matrix().allFinite() ||
        (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-9)
      std::abort();
  }
  if (orbed::CheckHologramScene(orbed::hl2ss::HologramSceneMessage(scene, 0))) std::abort();
  return 0;
}
