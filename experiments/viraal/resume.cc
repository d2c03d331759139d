#include "experiments/viraal/resume.h"

#include <cmath>
#include <stdexcept>

namespace orbed::scenario {
namespace {

bool SameJoints(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!(std::abs(a[i] - b[i]) <= 1e-9)) return false;
  }
  return true;
}

}  // namespace

std::vector<viraal::SessionResult> KeptSessions(const viraal::RunResults& earlier, const std::string& run_id,
                                                uint64_t seed, const viraal::ScenarioConfig& config) {
  const auto refuse = [&](const std::string& why) {
    return std::invalid_argument("cannot resume run '" + earlier.run_id + "': " + why);
  };
  if (earlier.ok) throw refuse("it completed (status ok): there is nothing left to run");
  if (earlier.run_id != run_id) throw refuse("this run's id is '" + run_id + "'");
  if (earlier.seed != seed) {
    throw refuse("its seed was " + std::to_string(earlier.seed) + ", this conductor's is " +
                 std::to_string(seed));
  }
  if (earlier.landmarks != config.landmarks) throw refuse("its landmarks are not this scenario's");
  const auto& configurations = config.configurations_deg;
  bool same_configurations = earlier.configurations_deg.size() == configurations.size();
  for (size_t k = 0; same_configurations && k < configurations.size(); ++k) {
    same_configurations = SameJoints(earlier.configurations_deg[k], configurations[k]);
  }
  if (!same_configurations) throw refuse("its configurations are not this scenario's");
  if (earlier.sessions.size() > config.modes.size())
    throw refuse("it has more sessions than this scenario's modes");

  std::vector<viraal::SessionResult> kept;
  for (size_t m = 0; m < earlier.sessions.size(); ++m) {
    const viraal::SessionResult& s = earlier.sessions[m];
    const viraal::ModeSpec& mode = config.modes[m];
    const std::string where = "session " + std::to_string(m) + " ('" + s.session_id + "')";
    if (s.mode != mode.name || s.session_id != run_id + "-" + mode.name ||
        s.display_mode != mode.display_mode || s.num_mirrors != mode.num_mirrors) {
      throw refuse(where + " is not this scenario's mode " + mode.name + " (session '" + run_id + "-" +
                   mode.name + "', " + std::to_string(mode.num_mirrors) + " mirror(s))");
    }
    const std::vector<std::string> waypoints =
        mode.num_mirrors > 0 ? config.capture_waypoints : std::vector<std::string>{};
    if (s.capture_waypoints != waypoints) {
      const auto list = [](const std::vector<std::string>& names) {
        std::string text;
        for (const std::string& n : names) text += (text.empty() ? "" : ", ") + n;
        return names.empty() ? std::string("the headset's own") : "[" + text + "]";
      };
      throw refuse(where + " captured at " + list(s.capture_waypoints) + ", this scenario at " +
                   list(waypoints));
    }
    if (static_cast<int>(s.trials.size()) > config.trials) {
      throw refuse(where + " has " + std::to_string(s.trials.size()) + " trials, the scenario " +
                   std::to_string(config.trials));
    }
    for (size_t i = 0; i < s.trials.size(); ++i) {
      if (s.trials[i].index != static_cast<int>(i) ||
          !SameJoints(s.trials[i].q_deg, configurations[i % configurations.size()])) {
        throw refuse(where + " trial " + std::to_string(i) + " is not trial " + std::to_string(i) +
                     " at configuration " + std::to_string(i % configurations.size()));
      }
    }
    if (s.mean && static_cast<int>(s.trials.size()) != config.trials) {
      throw refuse(where + " has a mean of " + std::to_string(s.trials.size()) + " trial(s)");
    }
    if (!kept.empty() && !kept.back().mean) throw refuse(where + " follows a session that did not finish");
    kept.push_back(s);
  }
  if (kept.size() == config.modes.size() && kept.back().mean) throw refuse("every session has its mean");
  return kept;
}

}  // namespace orbed::scenario
