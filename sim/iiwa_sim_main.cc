/// @file
/// orbed-iiwa-sim: a simulated KUKA LBR iiwa 7 R800 in the OR scene, moved like a hand-guided arm
/// in manual mode (speed- and limit-bounded, stops before a collision; see sim/iiwa_sim.h); flags
/// and exit codes: sim/iiwa_sim_cli.h.
/// Subscribes: IIWA_COMMAND (iiwa_command_t = Drake's lcmt_iiwa_command), PLAN_CHECK_REQUEST.
/// Publishes:  IIWA_STATUS (iiwa_status_t = Drake's lcmt_iiwa_status), ROBOT_STATE and
///             COLLISION_STATUS every --period-s (200 Hz by default); PLAN_CHECK_REPLY per
///             request; PROCESS_STATUS at 1 Hz. Channel names can be overridden by flags.
#include <iostream>

#include "sim/iiwa_sim_cli.h"

int main(int argc, char** argv) { return orbed::sim::RunIiwaSim(argc, argv, std::cout, std::cerr); }
