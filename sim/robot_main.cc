/// @file
/// orbed-robot: forward kinematics, collision check and trocar IK of the iiwa 7 model, JSON on
/// stdout (see sim/robot_tool.h). Publishes and subscribes nothing.
#include <iostream>

#include "sim/robot_tool.h"

int main(int argc, char** argv) { return orbed::sim::RunRobotTool(argc, argv, std::cout, std::cerr); }
