#include "procs/launcher/launch_file.h"

#include <csignal>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

extern char** environ;

namespace orbed::launcher {
namespace {

std::string Where(const std::string& path, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.line < 0) return path;
  return path + ":" + std::to_string(mark.line + 1);
}

[[noreturn]] void Fail(const std::string& path, const YAML::Node& node, const std::string& what) {
  throw LaunchFileError(Where(path, node) + ": " + what);
}

void CheckKeys(const std::string& path, const YAML::Node& map, const std::set<std::string>& allowed,
               const std::string& context) {
  for (const auto& item : map) {
    if (!item.first.IsScalar()) Fail(path, item.first, "a key in " + context + " must be a plain word");
    const std::string key = item.first.as<std::string>();
    if (allowed.count(key) == 0) {
      std::string list;
      for (const std::string& k : allowed) list += (list.empty() ? "" : ", ") + k;
      Fail(path, item.first, "unknown key '" + key + "' in " + context + "; expected one of: " + list);
    }
  }
}

std::string GetString(const std::string& path, const YAML::Node& node, const std::string& key,
                      const std::string& context) {
  const YAML::Node value = node[key];
  if (!value) Fail(path, node, context + " needs '" + key + "' (a string)");
  if (!value.IsScalar()) Fail(path, value, "'" + key + "' in " + context + " must be a string");
  return value.as<std::string>();
}

template <class T>
T GetScalar(const std::string& path, const YAML::Node& node, const std::string& key, T fallback,
            const std::string& expected) {
  const YAML::Node value = node[key];
  if (!value) return fallback;
  try {
    if (!value.IsScalar()) throw YAML::Exception(value.Mark(), "not a scalar");
    return value.as<T>();
  } catch (const YAML::Exception&) {
    Fail(path, value, "'" + key + "' must be " + expected);
  }
}

ProcessSpec ParseProcess(const std::string& path, const YAML::Node& node,
                         const std::map<std::string, std::string>& environment) {
  if (!node.IsMap()) Fail(path, node, "a process must be a map with at least name and command");
  ProcessSpec spec;
  spec.name = GetString(path, node, "name", "process");
  const std::string context = "process '" + spec.name + "'";
  CheckKeys(path, node,
            {"name", "command", "args", "env", "required", "respawn", "stop_signal", "stop_timeout_sec",
             "ready", "ready_timeout_sec", "exit_stops_all"},
            context);
  if (spec.name.empty() || spec.name.find_first_of(" \t/") != std::string::npos) {
    Fail(path, node["name"], "process name '" + spec.name + "' must be non-empty, no spaces or '/'");
  }
  auto expand = [&](const std::string& text, const YAML::Node& where) {
    try {
      return ExpandVariables(text, environment);
    } catch (const std::invalid_argument& e) {
      Fail(path, where, std::string(e.what()) + " (in " + context + ")");
    }
  };
  spec.command = expand(GetString(path, node, "command", context), node["command"]);
  if (const YAML::Node args = node["args"]) {
    if (!args.IsSequence()) Fail(path, args, "'args' of " + context + " must be a list of strings");
    for (const auto& arg : args) {
      if (!arg.IsScalar()) Fail(path, arg, "each arg of " + context + " must be a string");
      spec.args.push_back(expand(arg.as<std::string>(), arg));
    }
  }
  if (const YAML::Node env = node["env"]) {
    if (!env.IsMap()) Fail(path, env, "'env' of " + context + " must be a map of strings");
    for (const auto& item : env) {
      if (!item.first.IsScalar()) Fail(path, item.first, "env names must be plain words");
      if (!item.second.IsScalar()) Fail(path, item.second, "env values must be strings");
      spec.env[item.first.as<std::string>()] = expand(item.second.as<std::string>(), item.second);
    }
  }
  spec.required = GetScalar<bool>(path, node, "required", true, "true or false");
  spec.respawn = GetScalar<bool>(path, node, "respawn", false, "true or false");
  spec.exit_stops_all = GetScalar<bool>(path, node, "exit_stops_all", false, "true or false");
  const std::string signal_name =
      GetScalar<std::string>(path, node, "stop_signal", "SIGINT", "a signal name");
  spec.stop_signal = SignalFromName(signal_name);
  if (spec.stop_signal < 0) {
    Fail(path, node["stop_signal"],
         "unknown stop_signal '" + signal_name +
             "'; expected SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, "
             "SIGUSR2 or SIGKILL");
  }
  spec.stop_timeout_sec = GetScalar<double>(path, node, "stop_timeout_sec", 5.0, "a number of seconds");
  spec.ready_timeout_sec = GetScalar<double>(path, node, "ready_timeout_sec", 10.0, "a number of seconds");
  if (!(spec.stop_timeout_sec >= 0) || !(spec.ready_timeout_sec > 0)) {
    Fail(path, node, "stop_timeout_sec must be >= 0 and ready_timeout_sec > 0 in " + context);
  }
  const std::string ready = GetScalar<std::string>(path, node, "ready", "heartbeat", "a string");
  if (ready == "heartbeat") {
    spec.ready = ReadyCheck::kHeartbeat;
  } else if (ready == "none") {
    spec.ready = ReadyCheck::kNone;
  } else {
    Fail(path, node["ready"], "unknown ready '" + ready + "'; expected heartbeat or none");
  }
  return spec;
}

}  // namespace

std::string ExpandVariables(const std::string& text, const std::map<std::string, std::string>& environment) {
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    if (text.compare(i, 2, "${") == 0) {
      const size_t end = text.find('}', i + 2);
      if (end == std::string::npos) throw std::invalid_argument("unterminated ${ in '" + text + "'");
      const std::string name = text.substr(i + 2, end - i - 2);
      const auto it = environment.find(name);
      if (it == environment.end()) {
        throw std::invalid_argument("variable ${" + name + "} is not set");
      }
      out += it->second;
      i = end + 1;
    } else {
      out += text[i++];
    }
  }
  return out;
}

int SignalFromName(const std::string& name) {
  static const std::map<std::string, int> kSignals = {
      {"SIGINT", SIGINT},   {"SIGTERM", SIGTERM}, {"SIGHUP", SIGHUP},  {"SIGQUIT", SIGQUIT},
      {"SIGUSR1", SIGUSR1}, {"SIGUSR2", SIGUSR2}, {"SIGKILL", SIGKILL}};
  const auto it = kSignals.find(name);
  return it == kSignals.end() ? -1 : it->second;
}

std::map<std::string, std::string> CurrentEnvironment() {
  std::map<std::string, std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    const size_t eq = entry.find('=');
    if (eq != std::string::npos) env[entry.substr(0, eq)] = entry.substr(eq + 1);
  }
  return env;
}

LaunchSpec ParseLaunchYamlUnchecked(const std::string& yaml, const std::string& path,
                                    const std::map<std::string, std::string>& environment);

LaunchSpec ParseLaunchYaml(const std::string& yaml, const std::string& path,
                           const std::map<std::string, std::string>& environment) {
  try {
    return ParseLaunchYamlUnchecked(yaml, path, environment);
  } catch (const YAML::Exception& e) {
    // Anything the explicit checks did not anticipate (a map used as a key, ...).
    throw LaunchFileError(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

LaunchSpec ParseLaunchYamlUnchecked(const std::string& yaml, const std::string& path,
                                    const std::map<std::string, std::string>& environment) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::ParserException& e) {
    throw LaunchFileError(path + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax: " + e.msg);
  }
  if (!root.IsMap()) Fail(path, root, "a launch file must be a map with a 'groups' list");
  CheckKeys(path, root, {"name", "groups"}, "the launch file");
  LaunchSpec spec;
  spec.path = path;
  spec.name = GetScalar<std::string>(path, root, "name", "orbed", "a string");
  const YAML::Node groups = root["groups"];
  if (!groups || !groups.IsSequence() || groups.size() == 0) {
    Fail(path, root, "'groups' must be a non-empty list of {name, processes}");
  }
  std::set<std::string> names;
  for (const auto& group_node : groups) {
    if (!group_node.IsMap()) Fail(path, group_node, "each group must be a map {name, processes}");
    CheckKeys(path, group_node, {"name", "processes"}, "a group");
    GroupSpec group;
    group.name = GetString(path, group_node, "name", "group");
    const YAML::Node processes = group_node["processes"];
    if (!processes || !processes.IsSequence() || processes.size() == 0) {
      Fail(path, group_node, "group '" + group.name + "' needs a non-empty 'processes' list");
    }
    for (const auto& process_node : processes) {
      ProcessSpec process = ParseProcess(path, process_node, environment);
      if (!names.insert(process.name).second) {
        Fail(path, process_node, "process name '" + process.name + "' is used twice");
      }
      group.processes.push_back(std::move(process));
    }
    spec.groups.push_back(std::move(group));
  }
  return spec;
}

LaunchSpec LoadLaunchFile(const std::string& path, const std::map<std::string, std::string>& environment) {
  std::ifstream in(path);
  if (!in) throw LaunchFileError(path + ": cannot read the launch file");
  std::stringstream text;
  text << in.rdbuf();
  return ParseLaunchYaml(text.str(), path, environment);
}

}  // namespace orbed::launcher
