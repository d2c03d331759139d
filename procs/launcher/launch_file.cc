#include "procs/launcher/launch_file.h"

#include <cctype>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "base/yaml_fields.h"

extern char** environ;

namespace orbed::launcher {
namespace {

const std::vector<std::string> kSignalNames = {"SIGINT",  "SIGTERM", "SIGHUP", "SIGQUIT",
                                               "SIGUSR1", "SIGUSR2", "SIGKILL"};

bool IsHostName(const std::string& host) {
  return !host.empty() && host.size() <= 64 && host.find_first_of(" \t/") == std::string::npos;
}

// What the files of one launch share while they are read: the names taken so far, the files
// being read (an include of one of them is a cycle), and the arguments' values (declared in the
// first pass over the files, used in the second).
struct ReadState {
  std::set<std::string> process_names, group_names;
  std::vector<std::string> chain;
  bool declaring = true;                      // the first pass: only `arguments`
  std::map<std::string, std::string> values;  // argument name -> value (given, else default)
  std::map<std::string, std::string> given;   // what the command line gave
};

// `key` is the process's dotted path, e.g. "groups[0].processes[1]".
ProcessSpec ParseProcess(const YamlFields& f, const YAML::Node& node, const std::string& key,
                         const std::map<std::string, std::string>& environment, const ReadState& state) {
  if (!node.IsMap()) f.Fail(node, key, "expected a mapping with at least name and command");
  f.CheckKeys(node, key,
              {"name", "command", "host", "args", "env", "required", "respawn", "stop_signal",
               "stop_timeout_s", "ready", "ready_timeout_s", "exit_stops_all"});
  ProcessSpec spec;
  spec.name = f.String(f.Required(node, "name", key + ".name", "a string"), key + ".name");
  if (spec.name.empty() || spec.name.find_first_of(" \t/") != std::string::npos) {
    f.Fail(node["name"], key + ".name",
           "expected a non-empty name without spaces or '/', got '" + spec.name + "'");
  }
  auto expand = [&](const std::string& text, const YAML::Node& where, const std::string& where_key) {
    try {
      return ExpandArguments(ExpandVariables(text, environment), state.values);
    } catch (const std::invalid_argument& e) {
      f.Fail(where, where_key, std::string(e.what()) + " (in process '" + spec.name + "')");
    }
  };
  const YAML::Node command = f.Required(node, "command", key + ".command", "a string");
  spec.command = expand(f.String(command, key + ".command"), command, key + ".command");
  if (const YAML::Node host = node["host"]) {
    spec.host = expand(f.String(host, key + ".host"), host, key + ".host");
    if (!IsHostName(spec.host)) {
      f.Fail(host, key + ".host", "expected a host name without spaces or '/', got '" + spec.host + "'");
    }
  }
  if (const YAML::Node args = node["args"]) {
    if (!args.IsSequence()) f.Fail(args, key + ".args", "expected a list of strings");
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string k = key + ".args[" + std::to_string(i) + "]";
      if (!args[i].IsMap()) {
        spec.args.push_back(expand(f.String(args[i], k), args[i], k));
        continue;
      }
      // {if: NAME, args: [...]}: the list when argument NAME is set.
      f.CheckKeys(args[i], k, {"if", "args"});
      const YAML::Node name = f.Required(args[i], "if", k + ".if", "the name of an argument");
      const auto value = state.values.find(f.String(name, k + ".if"));
      if (value == state.values.end()) {
        f.Fail(name, k + ".if", "expected a declared argument, got '" + name.Scalar() + "'");
      }
      const YAML::Node list = f.Required(args[i], "args", k + ".args", "a list of strings");
      if (!list.IsSequence()) f.Fail(list, k + ".args", "expected a list of strings");
      for (std::size_t j = 0; j < list.size(); ++j) {
        const std::string kj = k + ".args[" + std::to_string(j) + "]";
        const std::string text = expand(f.String(list[j], kj), list[j], kj);
        if (!value->second.empty()) spec.args.push_back(text);
      }
    }
  }
  if (const YAML::Node env = node["env"]) {
    if (!env.IsMap()) f.Fail(env, key + ".env", "expected a mapping of strings");
    for (const auto& item : env) {
      if (!item.first.IsScalar()) f.Fail(item.first, key + ".env", "expected plain words as variable names");
      const std::string k = key + ".env." + item.first.Scalar();
      spec.env[item.first.Scalar()] = expand(f.String(item.second, k), item.second, k);
    }
  }
  spec.required = f.BoolOr(node, "required", key, spec.required);
  spec.respawn = f.BoolOr(node, "respawn", key, spec.respawn);
  spec.exit_stops_all = f.BoolOr(node, "exit_stops_all", key, spec.exit_stops_all);
  spec.stop_signal = SignalFromName(f.OneOfOr(node, "stop_signal", key, "SIGINT", kSignalNames));
  spec.stop_timeout_s = f.NumberOr(node, "stop_timeout_s", key, spec.stop_timeout_s, 0,
                                   std::numeric_limits<double>::infinity(), "s");
  spec.ready_timeout_s = f.PositiveOr(node, "ready_timeout_s", key, spec.ready_timeout_s, "s");
  const std::string ready = f.OneOfOr(node, "ready", key, "heartbeat", {"heartbeat", "none"});
  spec.ready = ready == "heartbeat" ? ReadyCheck::kHeartbeat : ReadyCheck::kNone;
  return spec;
}

constexpr int kMaxIncludeDepth = 8;
constexpr std::uintmax_t kMaxLaunchFileBytes = 1 << 20;  // a device or a huge file is no launch file

void ReadLaunchFile(const std::string& path, const std::map<std::string, std::string>& environment,
                    ReadState* state, LaunchSpec* spec);

// The file's `arguments:` into spec->arguments and state->values (the given value, else the default).
void DeclareArguments(const YamlFields& f, const YAML::Node& root, ReadState* state, LaunchSpec* spec) {
  const YAML::Node arguments = root["arguments"];
  if (!arguments) return;
  if (!arguments.IsMap()) f.Fail(arguments, "arguments", "expected a mapping {name: {default, help}}");
  for (const auto& item : arguments) {
    const std::string name = item.first.IsScalar() ? item.first.Scalar() : "";
    const std::string key = "arguments." + name;
    try {
      ParseArgumentAssignment(name + "=");
    } catch (const std::invalid_argument&) {
      f.Fail(item.first, key, "expected a name of letters, digits and '_'");
    }
    if (state->values.count(name) != 0) {
      f.Fail(item.first, key, "expected an argument declared once, got '" + name + "' again");
    }
    if (!item.second.IsMap()) f.Fail(item.second, key, "expected a mapping {default, help}");
    f.CheckKeys(item.second, key, {"default", "help"});
    ArgumentSpec argument;
    argument.name = name;
    argument.default_value = f.StringOr(item.second, "default", key, "");
    argument.help = f.StringOr(item.second, "help", key, "");
    const auto given = state->given.find(name);
    argument.given = given != state->given.end();
    argument.value = argument.given ? given->second : argument.default_value;
    state->values[name] = argument.value;
    spec->arguments.push_back(argument);
  }
}

void ParseLaunch(const YAML::Node& root, const std::string& path,
                 const std::map<std::string, std::string>& environment, ReadState* state, LaunchSpec* spec) {
  const YamlFields f(path);
  if (!root.IsMap()) f.Fail(root, "(top level)", "expected a mapping with a 'groups' list");
  f.CheckKeys(root, "", {"name", "include", "groups", "placement", "arguments"});
  if (state->chain.empty()) spec->name = f.StringOr(root, "name", "", "orbed");  // the top file's
  state->chain.push_back(path);
  // Included files first, in order, relative to this file's folder.
  if (const YAML::Node include = root["include"]) {
    if (!include.IsSequence()) f.Fail(include, "include", "expected a list of launch files");
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    for (std::size_t i = 0; i < include.size(); ++i) {
      const std::string key = "include[" + std::to_string(i) + "]";
      std::string name = f.String(include[i], key);
      try {
        name = ExpandVariables(name, environment);
      } catch (const std::invalid_argument& e) {
        f.Fail(include[i], key, e.what());
      }
      const std::string included = (folder / name).lexically_normal().string();
      for (const std::string& open : state->chain) {
        if (std::filesystem::path(open).lexically_normal() == std::filesystem::path(included)) {
          f.Fail(include[i], key,
                 "expected a file not being read already, got '" + name + "' (an include cycle)");
        }
      }
      if (state->chain.size() > kMaxIncludeDepth) {
        f.Fail(include[i], key, "expected at most " + std::to_string(kMaxIncludeDepth) + " nested includes");
      }
      ReadLaunchFile(included, environment, state, spec);
    }
  }
  if (state->declaring) {
    DeclareArguments(f, root, state, spec);  // after the included files', as groups are
    state->chain.pop_back();
    return;
  }
  const YAML::Node groups = root["groups"];
  if (groups && !groups.IsSequence()) f.Fail(groups, "groups", "expected a list of {name, processes}");
  const std::size_t num_groups = groups ? groups.size() : 0;
  if (num_groups == 0 && spec->groups.empty()) {
    f.Fail(groups ? groups : root, "groups", "expected a non-empty list of {name, processes}");
  }
  for (std::size_t g = 0; g < num_groups; ++g) {
    const YAML::Node group_node = groups[g];
    const std::string key = "groups[" + std::to_string(g) + "]";
    if (!group_node.IsMap()) f.Fail(group_node, key, "expected a mapping {name, processes}");
    f.CheckKeys(group_node, key, {"name", "processes"});
    GroupSpec group;
    group.name = f.String(f.Required(group_node, "name", key + ".name", "a string"), key + ".name");
    if (!state->group_names.insert(group.name).second) {
      f.Fail(group_node["name"], key + ".name",
             "expected a name not used by another group (included ones too), got '" + group.name + "'");
    }
    const YAML::Node processes = group_node["processes"];
    if (!processes || !processes.IsSequence() || processes.size() == 0) {
      f.Fail(processes ? processes : group_node, key + ".processes",
             "expected a non-empty list of processes (group '" + group.name + "')");
    }
    for (std::size_t p = 0; p < processes.size(); ++p) {
      const std::string process_key = key + ".processes[" + std::to_string(p) + "]";
      ProcessSpec process = ParseProcess(f, processes[p], process_key, environment, *state);
      if (!state->process_names.insert(process.name).second) {
        f.Fail(processes[p]["name"], process_key + ".name",
               "expected a name not used by another process, got '" + process.name + "' (used twice)");
      }
      group.processes.push_back(std::move(process));
    }
    spec->groups.push_back(std::move(group));
  }
  // Placement last: it may move processes of the included files and of this one.
  if (const YAML::Node placement = root["placement"]) {
    if (!placement.IsMap()) f.Fail(placement, "placement", "expected a mapping {process: host}");
    for (const auto& item : placement) {
      const std::string name = item.first.IsScalar() ? item.first.Scalar() : "";
      const std::string key = "placement." + name;
      std::string host = f.String(item.second, key);
      try {
        host = ExpandArguments(ExpandVariables(host, environment), state->values);
      } catch (const std::invalid_argument& e) {
        f.Fail(item.second, key, e.what());
      }
      if (!IsHostName(host)) {
        f.Fail(item.second, key, "expected a host name without spaces or '/', got '" + host + "'");
      }
      ProcessSpec* placed = nullptr;
      for (GroupSpec& group : spec->groups) {
        for (ProcessSpec& process : group.processes) {
          if (process.name == name) placed = &process;
        }
      }
      if (placed == nullptr) {
        f.Fail(item.first, key, "expected the name of a process of this launch, got '" + name + "'");
      }
      placed->host = host;
    }
  }
  state->chain.pop_back();
}

void ParseLaunchText(const std::string& yaml, const std::string& path,
                     const std::map<std::string, std::string>& environment, ReadState* state,
                     LaunchSpec* spec) {
  try {
    ParseLaunch(YamlFields::LoadString(yaml, path), path, environment, state, spec);
  } catch (const LaunchFileError&) {
    throw;  // an included file's error, already in the launcher's form
  } catch (const YAML::Exception& e) {
    // Anything the explicit checks did not anticipate.
    throw LaunchFileError(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  } catch (const std::runtime_error& e) {
    // YamlFields' "file:line: key: expected ..." as the launcher's error type.
    throw LaunchFileError(e.what());
  }
}

void ReadLaunchFile(const std::string& path, const std::map<std::string, std::string>& environment,
                    ReadState* state, LaunchSpec* spec) {
  const std::string by = state->chain.empty() ? "" : " (included by " + state->chain.back() + ")";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw LaunchFileError(path + ": cannot read the launch file" + by);
  if (std::filesystem::file_size(path, ec) > kMaxLaunchFileBytes) {
    throw LaunchFileError(path + ": a launch file of over 1 MiB" + by);
  }
  std::ifstream in(path);
  if (!in) throw LaunchFileError(path + ": cannot read the launch file" + by);
  std::stringstream text;
  text << in.rdbuf();
  ParseLaunchText(text.str(), path, environment, state, spec);
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

std::string ExpandArguments(const std::string& text, const std::map<std::string, std::string>& values) {
  static const std::string kOpen = "$(arg ";
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    if (text.compare(i, kOpen.size(), kOpen) == 0) {
      const size_t end = text.find(')', i + kOpen.size());
      if (end == std::string::npos) throw std::invalid_argument("unterminated $(arg in '" + text + "'");
      const std::string name = text.substr(i + kOpen.size(), end - i - kOpen.size());
      const auto it = values.find(name);
      if (it == values.end()) throw std::invalid_argument("argument '" + name + "' is not declared");
      out += it->second;
      i = end + 1;
    } else {
      out += text[i++];
    }
  }
  return out;
}

std::pair<std::string, std::string> ParseArgumentAssignment(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("expected NAME=VALUE, got '" + text + "'");
  const std::string name = text.substr(0, eq);
  bool word = !name.empty() && name.size() <= 64;
  for (const char c : name) word = word && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
  if (!word)
    throw std::invalid_argument("expected NAME=VALUE with NAME of letters, digits and '_', got '" + text +
                                "'");
  return {name, text.substr(eq + 1)};
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

namespace {

// Two passes over the files: the first declares every argument, the second reads the rest with
// their values known. `read` reads the top file into the state and spec given.
template <typename Read>
LaunchSpec ReadTwice(const std::string& path, const std::map<std::string, std::string>& arguments,
                     Read read) {
  ReadState declared;
  declared.given = arguments;
  LaunchSpec spec;
  spec.path = path;
  read(&declared, &spec);
  for (const auto& [name, value] : arguments) {
    if (declared.values.count(name) == 0) {
      std::string names;
      for (const ArgumentSpec& a : spec.arguments) names += (names.empty() ? "" : ", ") + a.name;
      throw LaunchFileError(path + ": --arg " + name + ": the launch declares no argument '" + name +
                            "' (it has: " + (names.empty() ? "none" : names) + ")");
    }
  }
  ReadState state;
  state.declaring = false;
  state.values = declared.values;
  LaunchSpec full;
  full.path = path;
  read(&state, &full);
  full.arguments = spec.arguments;
  return full;
}

}  // namespace

LaunchSpec ParseLaunchYaml(const std::string& yaml, const std::string& path,
                           const std::map<std::string, std::string>& environment,
                           const std::map<std::string, std::string>& arguments) {
  return ReadTwice(path, arguments, [&](ReadState* state, LaunchSpec* spec) {
    state->chain.reserve(kMaxIncludeDepth + 2);
    ParseLaunchText(yaml, path, environment, state, spec);
  });
}

LaunchSpec LoadLaunchFile(const std::string& path, const std::map<std::string, std::string>& environment,
                          const std::map<std::string, std::string>& arguments) {
  return ReadTwice(path, arguments, [&](ReadState* state, LaunchSpec* spec) {
    ReadLaunchFile(path, environment, state, spec);
  });
}

}  // namespace orbed::launcher
