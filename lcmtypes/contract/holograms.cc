#include "lcmtypes/contract/holograms.h"

#include <cmath>
#include <set>
#include <string>

#include "lcmtypes/contract/validation.h"

namespace orbed {

std::optional<Refusal> CheckHologramScene(const orbed::hologram_scene_t& m) {
  using M = orbed::hologram_scene_t;
  const auto n = static_cast<std::size_t>(m.num_holograms);
  if (m.num_holograms < 0 || m.num_holograms > M::MAX_HOLOGRAMS || m.id.size() != n || m.kind.size() != n ||
      m.X_WG.size() != n || m.scale.size() != n || m.rgba.size() != n || m.active.size() != n) {
    return Refusal{"num_holograms", "num_holograms " + std::to_string(m.num_holograms) + " out of [0, " +
                                        std::to_string(M::MAX_HOLOGRAMS) + "] or not the arrays' length"};
  }
  if (m.revision < 0) return Refusal{"num_holograms", "revision " + std::to_string(m.revision) + " < 0"};
  std::set<std::int32_t> ids;
  for (std::size_t i = 0; i < n; ++i) {
    const std::string which = "hologram " + std::to_string(i);
    if (m.id[i] == 0 || !ids.insert(m.id[i]).second)
      return Refusal{"id", which + ": id " + std::to_string(m.id[i]) + " is 0 or repeated"};
    if (m.kind[i] < M::KIND_SPHERE || m.kind[i] > M::KIND_TEXT)
      return Refusal{"kind", which + ": kind " + std::to_string(m.kind[i]) + " unknown"};
    const std::string pose_error = CheckWorldPose(m.X_WG[i], "X_WG");
    if (!pose_error.empty()) return Refusal{"pose", which + ": " + pose_error};
    for (double s : m.scale[i]) {
      if (!(std::abs(s) <= kMaxHologramScale))
        return Refusal{"scale", which + ": scale " + std::to_string(s) + " not finite or beyond 1000"};
    }
    for (float c : m.rgba[i]) {
      if (!std::isfinite(c)) return Refusal{"rgba", which + ": colour not finite"};
    }
  }
  return std::nullopt;
}

}  // namespace orbed
