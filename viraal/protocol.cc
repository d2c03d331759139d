#include "viraal/protocol.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/registration_t.hpp>

#include "base/number_list.h"

namespace orbed::viraal {
namespace {

// Every failure names the source, the line, the key and what was expected.
[[noreturn]] void FailAt(const std::string& source, const YAML::Node& node, const std::string& key,
                         const std::string& expected) {
  std::string where = source;
  if (node && node.Mark().line >= 0) where += ":" + std::to_string(node.Mark().line + 1);
  throw std::runtime_error(where + ": " + key + ": " + expected);
}

double NumberAt(const std::string& source, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar()) FailAt(source, node, key, "expected a number");
  double v = 0;
  try {
    v = node.as<double>();
  } catch (const YAML::Exception&) {
    FailAt(source, node, key, "expected a number, got '" + node.Scalar() + "'");
  }
  if (!std::isfinite(v)) FailAt(source, node, key, "expected a finite number");
  return v;
}

int IntAt(const std::string& source, const YAML::Node& node, const std::string& key, int lo) {
  const double v = NumberAt(source, node, key);
  if (v != std::floor(v) || v < lo || v > 1e6) {
    FailAt(source, node, key, "expected a whole number >= " + std::to_string(lo) + ", got " + node.Scalar());
  }
  return static_cast<int>(v);
}

std::vector<std::string> StringsAt(const std::string& source, const YAML::Node& node,
                                   const std::string& key) {
  if (!node.IsSequence() || node.size() == 0) FailAt(source, node, key, "expected a non-empty list of names");
  std::vector<std::string> out;
  for (size_t i = 0; i < node.size(); ++i) {
    if (!node[i].IsScalar()) FailAt(source, node[i], key + "[" + std::to_string(i) + "]", "expected a name");
    out.push_back(node[i].Scalar());
  }
  return out;
}

}  // namespace

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
  if (config.trials < 1) throw std::invalid_argument("trials must be >= 1");
  if (config.modes.empty()) throw std::invalid_argument("modes: at least one mode is needed");
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

ScenarioConfig LoadScenarioFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the scenario file");
  std::stringstream ss;
  ss << in.rdbuf();
  return LoadScenarioString(ss.str(), path);
}

ScenarioConfig LoadScenarioString(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  if (!root.IsMap()) FailAt(source, root, "(top level)", "expected a mapping of trials, modes, ...");
  const std::set<std::string> allowed = {
      "trials", "modes", "reflective_mirrors", "method", "configurations_deg", "landmarks"};
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (!allowed.count(key)) {
      FailAt(
          source, kv.first, key,
          "unknown key; expected one of: configurations_deg, landmarks, method, modes, reflective_mirrors, "
          "trials");
    }
  }
  const auto required = [&](const std::string& key) {
    if (!root[key]) FailAt(source, root, key, "missing");
    return root[key];
  };

  ScenarioConfig config;
  if (root["trials"]) config.trials = IntAt(source, root["trials"], "trials", 1);
  const int mirrors =
      root["reflective_mirrors"] ? IntAt(source, root["reflective_mirrors"], "reflective_mirrors", 1) : 1;
  if (root["method"]) {
    const YAML::Node node = root["method"];
    const std::string m = node.IsScalar() ? node.Scalar() : "";
    if (m == "chordal") {
      config.method = orbed::registration_t::METHOD_CHORDAL;
    } else if (m == "karcher") {
      config.method = orbed::registration_t::METHOD_KARCHER;
    } else if (m == "robust") {
      config.method = orbed::registration_t::METHOD_ROBUST;
    } else {
      FailAt(source, node, "method", "expected chordal, karcher or robust, got '" + m + "'");
    }
  }
  const YAML::Node modes = root["modes"];
  const std::vector<std::string> mode_names =
      modes ? StringsAt(source, modes, "modes") : std::vector<std::string>{"ar_reflective", "ar"};
  for (size_t i = 0; i < mode_names.size(); ++i) {
    try {
      config.modes.push_back(ModeFromName(mode_names[i], mirrors));
    } catch (const std::invalid_argument& e) {
      FailAt(source, modes[i], "modes[" + std::to_string(i) + "]", e.what());
    }
  }
  const YAML::Node configurations = required("configurations_deg");
  if (!configurations.IsSequence() || configurations.size() == 0) {
    FailAt(source, configurations, "configurations_deg", "expected a non-empty list of joint vectors [deg]");
  }
  for (size_t k = 0; k < configurations.size(); ++k) {
    const YAML::Node q = configurations[k];
    const std::string key = "configurations_deg[" + std::to_string(k) + "]";
    if (!q.IsSequence()) FailAt(source, q, key, "expected a list of joint angles [deg]");
    std::vector<double> values;
    for (size_t i = 0; i < q.size(); ++i)
      values.push_back(NumberAt(source, q[i], key + "[" + std::to_string(i) + "]"));
    config.configurations_deg.push_back(values);
  }
  config.landmarks = StringsAt(source, required("landmarks"), "landmarks");
  try {
    // The iiwa has 7 joints; the model check in ViraalScenario repeats this against the URDF.
    ValidateScenarioConfig(config, static_cast<int>(config.configurations_deg[0].size()));
  } catch (const std::invalid_argument& e) {
    FailAt(source, root, "configurations_deg", e.what());
  }
  return config;
}

}  // namespace orbed::viraal
