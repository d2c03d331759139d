#pragma once
/// @file
/// The one check of HOLOGRAMS (hologram_scene_t): the holograms a client placed through hl2ss's
/// remote Unity scene (orbed-hl2ss publishes them, orbed-hmd draws them). A message is refused
/// whole, keyed by the first field that fails:
///   num_holograms  in 0 .. MAX_HOLOGRAMS and equal to every array's length; revision >= 0;
///   id             every id != 0 and distinct;
///   kind           one of KIND_*;
///   pose           every X_WG a world pose (CheckWorldPose: unit quaternion, within 10 km);
///   scale          finite, |s| <= kMaxHologramScale on every axis;
///   rgba           finite.
/// Threading: pure function.

#include <optional>

#include <orbed/hologram_scene_t.hpp>

#include "lcmtypes/contract/session_control.h"

namespace orbed {

/// The largest |scale| of a hologram on one axis (a 1 km cube; Unity's primitives are 1 to 10 m).
inline constexpr double kMaxHologramScale = 1e3;

/// A Refusal{field, reason} when `msg` breaks the contract above, else nothing.
std::optional<Refusal> CheckHologramScene(const orbed::hologram_scene_t& msg);

}  // namespace orbed
