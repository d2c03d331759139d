#pragma once
/// @file
/// Resuming a ViRAAl run (orbed-scenario --resume): what a new conductor keeps of an earlier run's
/// results.json, checked against the run it is asked to do. Pure.
///
/// Kept: the sessions that have their mean (finished: not run again) and the trials of the first
/// session that has none (the conductor re-sends them to the registration server and the headset,
/// then runs that session's remaining trials); every later session is run. Since a trial is a
/// function of the run id, the session, its index and the scene (docs/design.md §8), the resumed
/// run's results equal an uninterrupted run's; results.json keeps poses through rotation matrices
/// and q in degrees, so a kept trial comes back to the registration server within about 1e-16 of
/// the original (its mean within the same: far below what any result prints).
///
/// Refused (std::invalid_argument with the reason): results whose status is "ok" (nothing to run)
/// or that have nothing left; another run id than the one asked for (it decides every trial);
/// another seed; configurations, landmarks, modes (order, display mode, mirrors), where a
/// session's displays captured (capture_waypoints) or a trial count that are not this scenario's; sessions
/// that are not the scenario's first ones in order with their ids "<run_id>-<mode>"; trials that are not 0,
/// 1, ... at their configurations (trial i at configuration i mod K, within 1e-9 deg); more trials than the
/// scenario's; a session with a mean but not all its trials; a session without a mean before one with a mean.
/// (The averaging method is not in results.json and is not checked: the scenario's is used.)

#include <cstdint>
#include <string>
#include <vector>

#include "experiments/viraal/protocol.h"
#include "experiments/viraal/results.h"

namespace orbed::scenario {

std::vector<viraal::SessionResult> KeptSessions(const viraal::RunResults& earlier, const std::string& run_id,
                                                uint64_t seed, const viraal::ScenarioConfig& config);

}  // namespace orbed::scenario
