#pragma once
/// @file
/// The `orbed-robot` command-line tool (thin main in robot_main.cc), as a library so that tests can
/// run it in-process. Commands, all printing one JSON document on stdout:
///   fk    --q-deg q1,...,q7 [--urdf FILE]
///         {"frame":"R","flange":{"position_m":[x,y,z],"rotation":[[..],[..],[..]]},
///          "tool_tip":{...},"links":{"iiwa_link_0":{...},...}}   (poses in the robot base frame R)
///   check --q-deg q1,...,q7 [--scene FILE] [--urdf FILE]
///         {"in_collision":b,"min_distance_m":d,"closest":{pair},"closest_self":{pair}|null,
///          "closest_environment":{pair}|null,"link_clearance_m":{...},...}
///         points in the scene frame W (= R without --scene); without --scene only self-collision.
///   ik    --scene FILE [--urdf FILE] [--seed N] [--starts N]
///         {"success":b,"q_deg":[...],"clearance_m":c,"position_error_m":e,"angle_error_deg":a,...}
///         the arm's clearance (links 0-7; the tool necessarily ends at the patient) maximised over
///         the redundancy; the full check (tool included) must be collision-free.
///   plan  --scene FILE [--urdf FILE] [--targets N] [--min-separation-deg D] [--min-clearance-m C]
///         [--seed N] [--starts N]
///         {"scene","min_separation_deg","min_clearance_m","seed","targets":[{"q_deg":[...],
///          "clearance_m","separation_deg","position_error_m","angle_error_deg"},...]}
///         distinct set-up targets for the scene's trocar (trocar_plan.h); orbed-guidance --plan.
/// Exit codes: 0 ok; 1 ik found no collision-free solution (JSON still printed, success false), or
/// plan could not find a target (the reason on stderr, no JSON);
/// 2 bad arguments or unreadable files (one line on stderr).
/// Files: --urdf defaults to $ORBED_SOURCE_DIR/sim/models/iiwa7.urdf, else the source tree the
/// tool was built from.

#include <ostream>

namespace orbed::sim {

int RunRobotTool(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::sim
