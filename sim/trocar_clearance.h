#pragma once
/// @file
/// The clearance objective for docking at a trocar (used by `orbed-robot ik` and the tests):
///   - a joint vector whose full check (every non-adjacent self pair, every robot-scene pair, the
///     tool included) collides scores its (<= 0) minimum distance;
///   - otherwise it scores the arm clearance c = the smallest clearance of the arm links (every
///     link but the tool) to the scene and to links at least 3 joints away, plus a tenth of the
///     mean stand-off of the arm links beyond c (each capped at 0.2 m) [m]. The second term matters:
///     the smallest clearance is usually the wrist's, near the patient, which the null space
///     (elbow swivel, roll about the tool) cannot move; maximising c alone leaves the elbow
///     wherever the start put it.
/// The tool is left out of the score because it necessarily ends at the patient; links two apart
/// because their small structural gaps (which cannot close within the limits) would otherwise
/// cap the score. Also the target in R from the scene.
///
/// Threading: the returned function owns two CollisionWorlds; call it from one thread at a time.

#include "sim/robot_model.h"
#include "sim/scene.h"
#include "sim/trocar_ik.h"

namespace orbed::sim {

/// `model` should already carry the scene's tool length.
ClearanceFunction MakeTrocarClearanceFunction(const RobotModel& model, const Scene& scene);
/// The arm clearance c alone [m] (the report of `orbed-robot ik`), or the <= 0 distance if the full
/// check collides.
ClearanceFunction MakeTrocarArmClearanceFunction(const RobotModel& model, const Scene& scene);

/// The scene's trocar expressed in the robot base frame R.
TrocarIkTarget TrocarTargetInBase(const Scene& scene);

}  // namespace orbed::sim
