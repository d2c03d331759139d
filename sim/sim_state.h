#pragma once
/// @file
/// orbed-iiwa-sim's state file: the arm's last measured configuration, so that a respawned sim
/// starts where the arm was (a real arm does not teleport) instead of at --initial-q-deg.
///
/// The file is a journal (runtime/journal.h) of exactly one record, "IIWA_STATUS": the
/// iiwa_status_t the sim published for that tick, whose joint_position_measured is q [rad].
/// WriteSimState replaces the file whole (temporary file + rename), so a reader finds the previous
/// state or the new one, never a mix. ReadSimState checks it like input from the bus: one whole
/// record and nothing after it, a well-formed iiwa_status_t (DecodeBounded), the model's joint
/// count, finite angles within the joint limits (ValidateJointVector, no slack); anything else is
/// refused with the reason, and the sim does not start (it would not know where the arm is).
///
/// Threading: plain functions.

#include <optional>
#include <string>

#include <Eigen/Core>
#include <orbed/iiwa_status_t.hpp>

#include "sim/robot_model.h"

namespace orbed::sim {

/// The record's channel.
inline constexpr char kSimStateRecord[] = "IIWA_STATUS";

/// q [rad] from the state file at `path`; nothing when there is no file. Throws std::runtime_error
/// "state file <path>: <why>" when the file is there but cannot be read or is not a valid state.
std::optional<Eigen::VectorXd> ReadSimState(const std::string& path, const RobotModel& model);

/// Replaces the state file by `status`. Returns false and sets *error on failure.
bool WriteSimState(const std::string& path, const orbed::iiwa_status_t& status, std::string* error);

}  // namespace orbed::sim
