#pragma once
/// @file
/// The YAML launch file of orbed-launch: groups started in order, processes within a group
/// started together. Schema (unknown keys are errors, so typos do not pass silently):
///
///   name: testbed                      # optional, for messages (the top file's)
///   include: [base.yaml]               # optional: launch files read first, their groups before
///                                      # this file's (paths relative to this file; ${VAR} expands;
///                                      # nested up to 8 deep, no cycles)
///   placement: {registration: hostB}   # optional: moves processes (this file's or included ones)
///                                      # to hosts, as their `host:` would
///   arguments:                         # optional: the launch's settings, given as
///     user_seed:                       # `orbed-launch FILE --arg user_seed=3`
///       default: ""                    # (a string; "" = not set)
///       help: "the emulated person"    # shown by `orbed-launch FILE --show-args`
///   groups:                            # may be left out when an include has groups
///     - name: recording
///       processes:
///         - name: logger               # unique; passed to the child as --name for heartbeats
///           command: orbed-logger      # no '/': looked up in the launcher's folder, then PATH
///           host: hostB                # optional: run by the deputy of that name (`orbed-launch
///                                      # --deputy hostB` on that machine); left out, or equal to
///                                      # the launcher's --host: started by the launcher itself
///           args: [--log-dir, "${ORBED_LOG_DIR}",
///                  {if: user_seed, args: [--user-seed, "$(arg user_seed)"]}]
///           env: {KEY: value}          # added to the launcher's environment
///           required: true             # its failure stops the testbed, exit != 0 (default true)
///           respawn: false             # restart when it dies (default false); never after exit
///                                      # code 74, "cannot write its output" (process.h)
///           stop_signal: SIGINT        # SIGINT | SIGTERM | SIGHUP | SIGQUIT | SIGUSR1 | SIGUSR2 | SIGKILL
///           stop_timeout_s: 5        # then SIGKILL (default 5)
///           ready: heartbeat           # heartbeat (first PROCESS_STATUS) | none (default heartbeat)
///           ready_timeout_s: 10      # (default 10)
///           exit_stops_all: false      # when it exits, stop the testbed with its exit status
///
/// ${VAR} in command, host, args and env values expands from the environment (orbed-launch adds
/// ORBED_BIN_DIR, its own folder, and ORBED_LAUNCH_FILE, the file it was given); an unset variable is an
/// error. The environment says where things are (folders, the bus); what a run is (the person, the
/// trials, the clock, configuration overlays) is an argument: $(arg NAME) expands to its value
/// (given, else its default) in the same places, and an args element {if: NAME, args: [...]} stands
/// for its list when NAME's value is not empty and for nothing when it is. An argument is declared
/// once in the file or the files it includes, before or after its use; using an undeclared one, or
/// giving one the launch does not declare, is an error. orbed-launch leaves ${ORBED_LOG_DIR} (when
/// set) to be expanded where the process runs: on another host, to that host's own folder of the
/// run (launcher.h). Group and process names are unique across a file and everything it includes.
/// The file is read with the project's checked YAML reader (base/yaml_fields.h): errors throw
/// LaunchFileError with "file:line: dotted.key: expected ..., got ...", e.g.
///   "testbed.yaml:12: groups[1].processes[0].stop_signal: expected SIGINT, ... or SIGKILL, got 'SIGFOO'".

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace orbed::launcher {

class LaunchFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class ReadyCheck { kHeartbeat, kNone };

struct ProcessSpec {
  std::string name;
  std::string command;
  /// "" = the launcher's own host; else the name of the deputy that runs it.
  std::string host;
  std::vector<std::string> args;
  std::map<std::string, std::string> env;
  bool required = true;
  bool respawn = false;
  int stop_signal = 2;  // SIGINT
  double stop_timeout_s = 5.0;
  ReadyCheck ready = ReadyCheck::kHeartbeat;
  double ready_timeout_s = 10.0;
  bool exit_stops_all = false;
};

struct GroupSpec {
  std::string name;
  std::vector<ProcessSpec> processes;
};

struct ArgumentSpec {
  std::string name;
  std::string default_value;
  std::string help;
  std::string value;  ///< the given value, else the default
  bool given = false;
};

struct LaunchSpec {
  std::string name;
  std::string path;
  std::vector<GroupSpec> groups;
  std::vector<ArgumentSpec> arguments;  ///< in the order declared (included files' first)
};

/// Parses a launch file. `environment` supplies ${VAR} values, `arguments` the $(arg NAME) values
/// given (each must be declared).
LaunchSpec LoadLaunchFile(const std::string& path, const std::map<std::string, std::string>& environment,
                          const std::map<std::string, std::string>& arguments = {});
/// The same from YAML text; `path` only names the source in errors.
LaunchSpec ParseLaunchYaml(const std::string& yaml, const std::string& path,
                           const std::map<std::string, std::string>& environment,
                           const std::map<std::string, std::string>& arguments = {});

/// Expands ${VAR}; throws std::invalid_argument naming an unset variable.
std::string ExpandVariables(const std::string& text, const std::map<std::string, std::string>& environment);
/// Expands $(arg NAME) from `values`; throws std::invalid_argument naming an undeclared argument.
std::string ExpandArguments(const std::string& text, const std::map<std::string, std::string>& values);

/// "NAME=VALUE" → {NAME, VALUE}; throws std::invalid_argument when there is no '=' or NAME is not
/// a word of letters, digits and '_'.
std::pair<std::string, std::string> ParseArgumentAssignment(const std::string& text);

/// "SIGINT" → 2 etc.; returns -1 for an unknown name.
int SignalFromName(const std::string& name);

/// The current process environment as a map.
std::map<std::string, std::string> CurrentEnvironment();

}  // namespace orbed::launcher
