#pragma once
/// @file
/// Where the files shipped in the source tree (the robot model, scenes, configs) are found at run
/// time: the one resolver every library and tool uses for its defaults.
///
///   root = $ORBED_SOURCE_DIR if set and non-empty, else the source tree orbed_robot_model was built
///          from (CMake's PROJECT_SOURCE_DIR, compiled in; valid while the build tree is).
///
/// Threading: reads the environment; call it from any thread (nothing sets the variable at run time).

#include <string>

namespace orbed {

/// The repository root as above, without a trailing '/'.
std::string SourceDir();

/// `relative` (e.g. "sim/models/iiwa7.urdf") under SourceDir().
std::string SourceTreePath(const std::string& relative);

}  // namespace orbed
