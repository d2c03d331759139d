#pragma once
/// @file
/// The `orbed-scenario` command line (thin main in scenario_main.cc), as a library so that tests
/// can run it in-process. It conducts the ViRAAl experiment over the bus (scenario_process.h) and
/// exits: 0 when every session finished, 1 with a one-line reason otherwise.
///
/// Flags: the common ones (flags.h: --lcm-url, --name, --seed, --duration-s, --log-level), and
///   --scenario FILE            scenario YAML (default experiments/viraal/viraal.yaml of the source tree)
///   --trials N, --modes a,b, --q-deg q1,...,q7 (repeatable)   overrides of the file
///   --run-id ID                sessions are <ID>-<mode>; default (or empty) viraal-<UTC time>
///   --results-dir DIR          folder of results.json (default $ORBED_LOG_DIR, else the working dir)
///   --urdf FILE                robot model for the landmark FK (default sim/models/iiwa7.urdf)
///   --tolerance-deg, --startup-timeout-s, --request-deadline-s,
///   --move-timeout-s         see ConductorOptions (viraal_conductor.h)
///   --<name>-channel           the nine channels, defaults from channels.h
///   --print RESULTS            no run: print the table of a run's results.json (or its folder)
///                              and exit 0 ok, 1 failed or unreadable, 3 stopped before the end
///
/// Streams: --help's usage and the run's progress lines and table go to `out`; flag errors and a
/// failure to start ("orbed-scenario: <reason>") to `err`. Log lines go to stderr (log.h).
/// Exit codes: 0 run completed or --help; 1 run failed or could not start; a bad flag CLI11's
/// parse error code (non-zero).

#include <ostream>
#include <string>

namespace orbed::scenario {

int RunScenario(int argc, const char* const* argv, std::ostream& out, std::ostream& err);
/// --print: the results table of `path` (results.json or its folder) on `out`; exit code as above.
int PrintResults(const std::string& path, std::ostream& out, std::ostream& err);

}  // namespace orbed::scenario
