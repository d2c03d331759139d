#pragma once
/// @file
/// The holograms an hl2ss client placed (HOLOGRAMS, hologram_scene_t, checked by
/// orbed::CheckHologramScene) as triangles for the headset's overlay: each shown hologram is
/// Unity's primitive at Unity's default size in its frame G, scaled along G's axes and posed at
/// X_WG (procs/hl2ss/unity_scene.h has the frames):
///   cube      1 m × 1 m × 1 m, centred;
///   sphere    diameter 1 m, centred;
///   cylinder  diameter 1 m, 2 m long along y_G, centred;
///   capsule   diameter 1 m, 2 m long along y_G end to end (cap centres 1 m apart), centred;
///   plane     10 m × 10 m in x_G z_G through the origin, seen from +y_G only;
///   quad      1 m × 1 m in x_G y_G through the origin, seen from +z_G only (Unity's −z);
///   text      not drawn.
/// Closed shapes wind outward; a scale with an odd number of negative axes mirrors the shape and
/// the winding is turned back; a zero scale axis leaves degenerate triangles out. Colour: the
/// client's RGB clamped to [0, 1]; the overlay's opacity is the hologram style's (the plugin's
/// default material is opaque: alpha is kept in the message, not drawn). Body ids:
/// kHologramBodyBase + the hologram's index in the message, so the overlay outlines each.
///
/// Frames: W (the headset's map), G a hologram's frame. Units: m.
/// Threading: pure functions.

#include <orbed/hologram_scene_t.hpp>

#include "render/scene_geometry.h"

namespace orbed::hmd {

/// Body ids of client holograms start here (the virtual robot's are its link bodies, far below).
inline constexpr int kHologramBodyBase = 1 << 20;

/// Appends the shown, drawable holograms of a checked `msg` to `mesh` (not cleared).
void TessellateHolograms(const orbed::hologram_scene_t& msg, const render::TessellationOptions& options,
                         render::Mesh* mesh);

}  // namespace orbed::hmd
