#include "experiments/viraal/protocol.h"

#include "lcmtypes/contract/alignment_trial.h"
#include "lcmtypes/contract/session_control.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/registration_t.hpp>

#include "base/number_list.h"
#include "base/yaml_fields.h"

namespace orbed::viraal {

void ApplyOverrides(ScenarioConfig* config, int trials, const std::string& modes,
                    const std::vector<std::string>& q_deg) {
  if (trials > 0) config->trials = trials;
  if (!modes.empty()) {
    int mirrors = 1;
    for (const ModeSpec& m : config->modes) {
      if (m.num_mirrors > 0) mirrors = m.num_mirrors;
    }
    config->modes.clear();
    std::stringstream list(modes);
    std::string name;
    while (std::getline(list, name, ',')) config->modes.push_back(ModeFromName(name, mirrors));
  }
  if (!q_deg.empty()) {
    config->configurations_deg.clear();
    for (const std::string& q : q_deg) config->configurations_deg.push_back(ParseJointList(q, "--q-deg"));
  }
}

ModeSpec ModeFromName(const std::string& name, int reflective_mirrors) {
  if (name == "ar_reflective") {
    return {name, orbed::alignment_trial_t::MODE_AR_REFLECTIVE, reflective_mirrors};
  }
  if (name == "ar") return {name, orbed::alignment_trial_t::MODE_AR, 0};
  throw std::invalid_argument("unknown mode '" + name + "', expected ar_reflective or ar");
}

std::vector<double> ParseJointList(const std::string& text, const std::string& what) {
  return ParseNumberList(text, what + " (q1,...,q7 in deg)");
}

void ValidateScenarioConfig(const ScenarioConfig& config, int num_joints) {
  if (config.trials < 1 || config.trials > kMaxTrialsPerSession) {
    throw std::invalid_argument("trials must be 1.." + std::to_string(kMaxTrialsPerSession) +
                                " (the most one headset session holds), not " +
                                std::to_string(config.trials));
  }
  if (config.modes.empty()) throw std::invalid_argument("modes: at least one mode is needed");
  for (const ModeSpec& m : config.modes) {
    if (m.num_mirrors > 0 && !config.capture_waypoints.empty() &&
        static_cast<int>(config.capture_waypoints.size()) != m.num_mirrors) {
      throw std::invalid_argument("capture_waypoints: " + std::to_string(config.capture_waypoints.size()) +
                                  " waypoint(s) for the " + std::to_string(m.num_mirrors) +
                                  " display(s) of mode " + m.name +
                                  ": one per display, or [] for the headset's own");
    }
  }
  for (const std::string& w : config.capture_waypoints) {
    if (!IsWaypointName(w))
      throw std::invalid_argument("capture_waypoints: '" + w + "' is not a waypoint name (1.." +
                                  std::to_string(kMaxWaypointNameLength) + " printable bytes, no spaces)");
  }
  std::set<std::string> seen;
  for (const ModeSpec& m : config.modes) {
    if (!seen.insert(m.name).second) throw std::invalid_argument("modes: '" + m.name + "' is listed twice");
  }
  if (config.method < orbed::registration_t::METHOD_CHORDAL ||
      config.method > orbed::registration_t::METHOD_ROBUST) {
    throw std::invalid_argument("method: out of range");
  }
  if (config.configurations_deg.empty())
    throw std::invalid_argument("configurations: at least one is needed");
  const size_t n = static_cast<size_t>(num_joints);
  for (size_t k = 0; k < config.configurations_deg.size(); ++k) {
    const auto& q = config.configurations_deg[k];
    if (q.size() != n) {
      throw std::invalid_argument("configuration " + std::to_string(k) + ": expected " + std::to_string(n) +
                                  " joint angles [deg], got " + std::to_string(q.size()));
    }
    for (double v : q) {
      if (!std::isfinite(v))
        throw std::invalid_argument("configuration " + std::to_string(k) + ": not finite");
    }
    for (size_t j = 0; j < k; ++j) {
      double max_diff = 0;
      for (size_t i = 0; i < n; ++i)
        max_diff = std::max(max_diff, std::abs(q[i] - config.configurations_deg[j][i]));
      if (max_diff <= 1.0) {
        throw std::invalid_argument("configurations " + std::to_string(j) + " and " + std::to_string(k) +
                                    " are the same (no joint differs by more than 1 deg); the paper's trials "
                                    "use distinct configurations");
      }
    }
  }
  if (config.landmarks.empty()) throw std::invalid_argument("landmarks: at least one is needed");
}

namespace {

ScenarioConfig LoadScenario(const YAML::Node& root, const std::string& source) {
  const YamlFields f(source);
  f.CheckKeys(root, "",
              {"trials", "modes", "reflective_mirrors", "method", "capture_waypoints", "configurations_deg",
               "landmarks"});
  ScenarioConfig config;
  config.trials = static_cast<int>(f.IntegerOr(root, "trials", "", config.trials, 1, kMaxTrialsPerSession));
  const int mirrors =
      static_cast<int>(f.IntegerOr(root, "reflective_mirrors", "", kDefaultReflectiveMirrors, 1, 1000000));
  if (root["method"]) {
    const std::string m = f.OneOf(root["method"], "method", {"chordal", "karcher", "robust"});
    config.method = m == "chordal"   ? orbed::registration_t::METHOD_CHORDAL
                    : m == "karcher" ? orbed::registration_t::METHOD_KARCHER
                                     : orbed::registration_t::METHOD_ROBUST;
  }
  // Without `modes`, the default modes by name (reflective_mirrors still applies).
  const YAML::Node modes = root["modes"];
  std::vector<std::string> mode_names;
  for (const ModeSpec& m : config.modes) mode_names.push_back(m.name);
  if (modes) mode_names = f.Strings(modes, "modes");
  config.modes.clear();
  for (size_t i = 0; i < mode_names.size(); ++i) {
    try {
      config.modes.push_back(ModeFromName(mode_names[i], mirrors));
    } catch (const std::invalid_argument& e) {
      f.Fail(modes[i], "modes[" + std::to_string(i) + "]", e.what());
    }
  }
  if (const YAML::Node w = root["capture_waypoints"]) {
    if (!w.IsSequence())
      f.Fail(w, "capture_waypoints", "expected a list of waypoint names ([] = the headset's)");
    if (w.size() > 0) config.capture_waypoints = f.Strings(w, "capture_waypoints");
  }
  const YAML::Node configurations = f.Required(root, "configurations_deg", "configurations_deg");
  if (!configurations.IsSequence() || configurations.size() == 0) {
    f.Fail(configurations, "configurations_deg", "expected a non-empty list of joint vectors [deg]");
  }
  const double inf = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < configurations.size(); ++k) {
    const YAML::Node q = configurations[k];
    const std::string key = "configurations_deg[" + std::to_string(k) + "]";
    if (!q.IsSequence()) f.Fail(q, key, "expected a list of joint angles [deg]");
    std::vector<double> values;
    for (size_t i = 0; i < q.size(); ++i) {
      values.push_back(f.Number(q[i], key + "[" + std::to_string(i) + "]", -inf, inf, "deg"));
    }
    config.configurations_deg.push_back(values);
  }
  config.landmarks = f.Strings(f.Required(root, "landmarks", "landmarks"), "landmarks");
  try {
    // The iiwa has 7 joints; the conductor repeats this check against the URDF.
    ValidateScenarioConfig(config, static_cast<int>(config.configurations_deg[0].size()));
  } catch (const std::invalid_argument& e) {
    f.Fail(root, "configurations_deg", e.what());
  }
  return config;
}

}  // namespace

ScenarioConfig LoadScenarioFile(const std::string& path) {
  return LoadScenario(YamlFields::LoadFile(path), path);
}

ScenarioConfig LoadScenarioString(const std::string& yaml_text, const std::string& source) {
  return LoadScenario(YamlFields::LoadString(yaml_text, source), source);
}

}  // namespace orbed::viraal
