#include "procs/launcher/deputy_protocol.h"

#include <cmath>
#include <cstring>
#include <set>

#include "procs/launcher/launch_file.h"

namespace orbed::launcher {
namespace {

bool NameOk(const std::string& name) { return !name.empty() && name.size() <= kMaxDeputyName; }

}  // namespace

std::string CheckDeputyCommand(const orbed::deputy_command_t& msg) {
  if (!NameOk(msg.launcher)) return "launcher: expected 1.." + std::to_string(kMaxDeputyName) + " bytes";
  if (!NameOk(msg.deputy)) return "deputy: expected 1.." + std::to_string(kMaxDeputyName) + " bytes";
  if (msg.launcher_start_utime <= 0) return "launcher_start_utime: expected > 0";
  if (msg.num_processes < 0 || static_cast<size_t>(msg.num_processes) > kMaxDeputyProcesses ||
      static_cast<size_t>(msg.num_processes) != msg.processes.size()) {
    return "num_processes: expected 0.." + std::to_string(kMaxDeputyProcesses) + " and the array's length";
  }
  std::set<std::string> names;
  for (const orbed::deputy_process_t& p : msg.processes) {
    if (!NameOk(p.name) || p.name.find_first_of(" \t/") != std::string::npos) {
      return "processes.name: expected 1.." + std::to_string(kMaxDeputyName) + " bytes without '/' or space";
    }
    const std::string at = "processes[" + p.name + "].";
    if (!names.insert(p.name).second) return at + "name: used twice";
    if (p.instance < 1) return at + "instance: expected >= 1";
    if (p.argc < 1 || static_cast<size_t>(p.argc) > kMaxArgc ||
        static_cast<size_t>(p.argc) != p.argv.size()) {
      return at + "argc: expected 1.." + std::to_string(kMaxArgc) + " and the array's length";
    }
    if (p.argv[0].empty()) return at + "argv[0]: expected a command";
    for (const std::string& arg : p.argv) {
      if (arg.size() > kMaxArgBytes)
        return at + "argv: an argument over " + std::to_string(kMaxArgBytes) + " bytes";
    }
    if (p.num_env < 0 || static_cast<size_t>(p.num_env) > kMaxEnv ||
        static_cast<size_t>(p.num_env) != p.env_key.size() || p.env_key.size() != p.env_value.size()) {
      return at + "num_env: expected 0.." + std::to_string(kMaxEnv) + " and both arrays' lengths";
    }
    for (size_t i = 0; i < p.env_key.size(); ++i) {
      if (!NameOk(p.env_key[i]) || p.env_key[i].find('=') != std::string::npos) {
        return at + "env_key: expected 1.." + std::to_string(kMaxDeputyName) + " bytes without '='";
      }
      if (p.env_value[i].size() > kMaxArgBytes)
        return at + "env_value: over " + std::to_string(kMaxArgBytes) + " bytes";
    }
    bool known_signal = false;
    for (const char* name : {"SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT", "SIGUSR1", "SIGUSR2", "SIGKILL"}) {
      known_signal = known_signal || SignalFromName(name) == p.stop_signal;
    }
    if (!known_signal)
      return at + "stop_signal: expected SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2 or SIGKILL";
    if (!std::isfinite(p.stop_timeout_s) || p.stop_timeout_s < 0 || p.stop_timeout_s > kMaxStopTimeoutS) {
      return at + "stop_timeout_s: expected a number in [0, " +
             std::to_string(static_cast<int>(kMaxStopTimeoutS)) + "]";
    }
  }
  if (!msg.run_dir.empty() && !RunDirOk(msg.run_dir)) {
    return "run_dir: expected one path component of 1.." + std::to_string(kMaxDeputyName) +
           " bytes (no '/', not '.' or '..')";
  }
  return "";
}

std::string CheckDeputyStatus(const orbed::deputy_status_t& msg) {
  if (!NameOk(msg.deputy)) return "deputy: expected 1.." + std::to_string(kMaxDeputyName) + " bytes";
  if (msg.launcher.size() > kMaxDeputyName)
    return "launcher: over " + std::to_string(kMaxDeputyName) + " bytes";
  if (msg.num_children < 0 || static_cast<size_t>(msg.num_children) > kMaxDeputyProcesses ||
      static_cast<size_t>(msg.num_children) != msg.children.size()) {
    return "num_children: expected 0.." + std::to_string(kMaxDeputyProcesses) + " and the array's length";
  }
  for (const orbed::deputy_child_t& c : msg.children) {
    if (!NameOk(c.name)) return "children.name: expected 1.." + std::to_string(kMaxDeputyName) + " bytes";
    if (c.instance < 1) return "children[" + c.name + "].instance: expected >= 1";
    if (c.pid < 0) return "children[" + c.name + "].pid: expected >= 0";
    if (c.state < orbed::deputy_child_t::STATE_RUNNING ||
        c.state > orbed::deputy_child_t::STATE_FAILED_TO_START) {
      return "children[" + c.name + "].state: expected 0..3";
    }
    if (c.num_last_lines < 0 || static_cast<size_t>(c.num_last_lines) > kMaxLastLines ||
        static_cast<size_t>(c.num_last_lines) != c.last_lines.size()) {
      return "children[" + c.name + "].num_last_lines: expected 0.." + std::to_string(kMaxLastLines) +
             " and the array's length";
    }
    for (const std::string& line : c.last_lines) {
      if (line.size() > kMaxLastLineBytes) {
        return "children[" + c.name + "].last_lines: a line over " + std::to_string(kMaxLastLineBytes) +
               " bytes";
      }
    }
  }
  return "";
}

std::string ExpandLogDir(const std::string& text, const std::string& dir) {
  const std::string variable = kLogDirVariable;
  std::string out = text;
  for (size_t at = out.find(variable); at != std::string::npos; at = out.find(variable, at + dir.size())) {
    out.replace(at, variable.size(), dir);
  }
  return out;
}

bool RunDirOk(const std::string& run_dir) {
  return NameOk(run_dir) && run_dir.find('/') == std::string::npos && run_dir != "." && run_dir != "..";
}

std::string DescribeExit(int exit_code, int term_signal) {
  if (term_signal != 0) return std::string("killed by signal ") + strsignal(term_signal);
  return "exited with code " + std::to_string(exit_code);
}

}  // namespace orbed::launcher
