#include "hmd_emulator/headset_trial.h"

#include <stdexcept>

#include "base/hash.h"

namespace orbed::hmd {

std::uint64_t TrialSeed(std::uint64_t seed, const std::string& session_id, std::int32_t index,
                        std::uint64_t purpose) {
  const std::uint64_t h = Fnv1a64(session_id);
  return SplitMix64(SplitMix64(SplitMix64(seed ^ h) ^ static_cast<std::uint64_t>(index)) ^ purpose);
}

TrialSetup MakeHeadsetTrialSetup(const HmdConfigSet& config, const HeadsetTrialInputs& inputs) {
  const int placed = static_cast<int>(config.hmd.displays.size());
  if (inputs.num_mirrors < 0 || inputs.num_mirrors > placed) {
    throw std::invalid_argument("headset trial: num_mirrors " + std::to_string(inputs.num_mirrors) +
                                ", the config places " + std::to_string(placed) + " display(s)");
  }
  TrialSetup setup;
  setup.X_WR = inputs.X_WR;
  setup.p_RQ = inputs.p_RQ;
  setup.walk = config.walk;
  setup.align_waypoint = config.hmd.align_waypoint;
  setup.settle_s = config.hmd.settle_s;
  setup.max_wait_s = config.hmd.max_wait_s;
  setup.max_repeats = config.hmd.max_repeats;
  for (const ScheduledFault& f : config.slam.faults) {
    if (f.AppliesTo(inputs.session_id, inputs.trial_index)) setup.faults.push_back(f.timed);
  }
  setup.intrinsics = geometry::Intrinsics::HoloLensPv();
  for (int i = 0; i < inputs.num_mirrors; ++i) {
    setup.capture_waypoints.push_back(config.hmd.displays[i].capture_waypoint);
  }
  return setup;
}

TrialOutcome RunHeadsetTrial(const HmdConfigSet& config, const HeadsetTrialInputs& inputs) {
  const TrialSetup setup = MakeHeadsetTrialSetup(config, inputs);
  SlamConfig slam = config.slam;
  slam.seed = TrialSeed(inputs.process_seed, inputs.session_id, inputs.trial_index, kSlamSeedPurpose);
  const std::uint64_t trial_seed =
      TrialSeed(inputs.process_seed, inputs.session_id, inputs.trial_index, kTrialSeedPurpose);
  const EmulatedUser user(config.user);
  return RunTrial(setup, slam, user, inputs.X_WV_start, trial_seed);
}

}  // namespace orbed::hmd
