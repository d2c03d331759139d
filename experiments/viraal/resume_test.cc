// Resume bookkeeping (resume.h): what an earlier run's results let a conductor keep, and every
// refusal, on the pinned run's results.json cut back to partial states.
#include "experiments/viraal/resume.h"

#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "experiments/viraal/protocol.h"
#include "experiments/viraal/results.h"

namespace orbed::scenario {
namespace {

viraal::ScenarioConfig Shipped() {
  return viraal::LoadScenarioFile(SourceTreePath(viraal::kDefaultScenarioRelativePath));
}

// The pinned run (2 sessions x 3 trials, seed 1), stopped after `trials` trials of session 1
// (0: session 0 only, with its mean) or, with `first_only`, after `trials` trials of session 0.
viraal::RunResults Stopped(int trials, bool first_only = false) {
  viraal::RunResults r =
      viraal::ReadResultsFile(SourceTreePath("tests/integration/testdata/viraal_pinned_results.json"));
  r.ok = false;
  r.partial = true;
  if (first_only) {
    r.sessions.resize(1);
    r.sessions[0].trials.resize(trials);
    r.sessions[0].mean.reset();
  } else {
    r.sessions[1].trials.resize(trials);
    r.sessions[1].mean.reset();
    if (trials == 0) r.sessions.resize(1);
  }
  return r;
}

TEST(Resume, KeepsTheFinishedSessionsAndTheTrialsOfTheOneInProgress) {
  const auto kept = KeptSessions(Stopped(2), "pinned", 1, Shipped());
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_TRUE(kept[0].mean.has_value());
  EXPECT_EQ(kept[0].trials.size(), 3u);
  EXPECT_FALSE(kept[1].mean.has_value());
  EXPECT_EQ(kept[1].trials.size(), 2u);
  EXPECT_EQ(KeptSessions(Stopped(0), "pinned", 1, Shipped()).size(), 1u);
  EXPECT_EQ(KeptSessions(Stopped(1, true), "pinned", 1, Shipped())[0].trials.size(), 1u);
  EXPECT_EQ(KeptSessions(Stopped(3, true), "pinned", 1, Shipped())[0].trials.size(), 3u);  // the mean is left
  // A run that failed before any session: nothing to keep, everything to run.
  viraal::RunResults failed = Stopped(0, true);
  failed.partial = false;
  failed.error = "orbed-iiwa-sim answered 2 of 3 PLAN_CHECK_REQUESTs within 5.0 s";
  failed.sessions.clear();
  EXPECT_TRUE(KeptSessions(failed, "pinned", 1, Shipped()).empty());
}

std::string RefusalOf(const viraal::RunResults& earlier, const std::string& run_id = "pinned",
                      uint64_t seed = 1, const viraal::ScenarioConfig& config = Shipped()) {
  try {
    KeptSessions(earlier, run_id, seed, config);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

viraal::RunResults With(const std::function<void(viraal::RunResults&)>& change, int trials = 2) {
  viraal::RunResults r = Stopped(trials);
  change(r);
  return r;
}

TEST(Resume, RefusesWhatDoesNotBelongToThisRun) {
  const std::string prefix = "cannot resume run 'pinned': ";
  EXPECT_EQ(RefusalOf(With([](viraal::RunResults& r) { r.ok = true; })),
            prefix + "it completed (status ok): there is nothing left to run");
  EXPECT_EQ(RefusalOf(Stopped(2), "other"), prefix + "this run's id is 'other'");
  EXPECT_EQ(RefusalOf(Stopped(2), "pinned", 2), prefix + "its seed was 1, this conductor's is 2");
  viraal::ScenarioConfig config = Shipped();
  config.configurations_deg[2][6] += 1.0;
  EXPECT_EQ(RefusalOf(Stopped(2), "pinned", 1, config),
            prefix + "its configurations are not this scenario's");
  config = Shipped();
  config.landmarks.pop_back();
  EXPECT_EQ(RefusalOf(Stopped(2), "pinned", 1, config), prefix + "its landmarks are not this scenario's");
  config = Shipped();
  std::swap(config.modes[0], config.modes[1]);
  EXPECT_NE(RefusalOf(Stopped(2), "pinned", 1, config).find("is not this scenario's mode ar"),
            std::string::npos);
  config = Shipped();
  config.trials = 2;
  EXPECT_NE(RefusalOf(Stopped(0), "pinned", 1, config).find("has 3 trials, the scenario 2"),
            std::string::npos);
  config.trials = 4;
  EXPECT_NE(RefusalOf(Stopped(0), "pinned", 1, config).find("has a mean of 3 trial(s)"), std::string::npos);
  config = Shipped();
  config.modes.pop_back();
  EXPECT_EQ(RefusalOf(Stopped(2), "pinned", 1, config),
            prefix + "it has more sessions than this scenario's modes");
  EXPECT_EQ(RefusalOf(Stopped(0), "pinned", 1, config), prefix + "every session has its mean");
  // The displays captured elsewhere than this scenario says (both ways round).
  config = Shipped();
  config.capture_waypoints = {"head_end"};
  EXPECT_EQ(
      RefusalOf(Stopped(2), "pinned", 1, config),
      prefix +
          "session 0 ('pinned-ar_reflective') captured at the headset's own, this scenario at [head_end]");
  EXPECT_EQ(KeptSessions(With([](viraal::RunResults& r) { r.sessions[0].capture_waypoints = {"head_end"}; }),
                         "pinned", 1, config)
                .size(),
            2u);
  EXPECT_EQ(
      RefusalOf(With([](viraal::RunResults& r) { r.sessions[0].capture_waypoints = {"head_end"}; })),
      prefix +
          "session 0 ('pinned-ar_reflective') captured at [head_end], this scenario at the headset's own");
}

TEST(Resume, RefusesTrialsAndSessionsOutOfOrder) {
  EXPECT_NE(RefusalOf(With([](viraal::RunResults& r) {
              r.sessions[1].trials[1].index = 2;
            })).find("session 1 ('pinned-ar') trial 1 is not trial 1 at configuration 1"),
            std::string::npos);
  EXPECT_NE(RefusalOf(With([](viraal::RunResults& r) {
              r.sessions[1].trials[0].q_deg[0] += 1e-6;
            })).find("trial 0 is not trial 0 at configuration 0"),
            std::string::npos);
  EXPECT_NE(RefusalOf(With([](viraal::RunResults& r) {
              r.sessions[0].session_id = "other-ar_reflective";
            })).find("session 0 ('other-ar_reflective') is not this scenario's mode ar_reflective"),
            std::string::npos);
  EXPECT_NE(RefusalOf(With([](viraal::RunResults& r) { r.sessions[1].num_mirrors = 1; })).find("mode ar "),
            std::string::npos);
  EXPECT_NE(RefusalOf(With([](viraal::RunResults& r) {
              r.sessions[0].mean.reset();
              r.sessions[1].trials.clear();
            })).find("follows a session that did not finish"),
            std::string::npos);
}

}  // namespace
}  // namespace orbed::scenario
