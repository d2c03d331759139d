#include "procs/registration_server/registration_server_process.h"

#include "base/log.h"

namespace orbed::registration {

namespace {

RegistrationServerOptions WithHeadsetChannels(RegistrationServerOptions o) {
  for (std::string* channel :
       {&o.session_control_channel, &o.trial_channel, &o.registration_channel, &o.landmark_request_channel,
        &o.landmark_channel, &o.misalignment_request_channel, &o.misalignment_channel}) {
    *channel = channels::ForHeadset(*channel, o.headset);
  }
  return o;
}

}  // namespace

RegistrationServer::RegistrationServer(const orbed::CommonFlags& flags,
                                       const RegistrationServerOptions& options)
    : Process(flags),
      options_(WithHeadsetChannels(options)),
      service_(options.service,
               [this](const std::string& key, const std::string& reason) { Reject(key, reason); }) {
  if (!options_.journal_path.empty()) {
    journal_ = std::make_unique<SessionJournal>(
        options_.journal_path, &service_,
        [this](const std::string& key, const std::string& reason) { Reject(key, reason); });
    ORBED_LOG(kInfo) << journal_->replay_summary();
  }
  Subscribe<orbed::session_control_t>(
      options_.session_control_channel,
      [this](const orbed::session_control_t& msg, const std::string&, int64_t) {
        if (auto state = HandleSessionControl(msg)) Publish(options_.registration_channel, *state);
      });
  Subscribe<orbed::alignment_trial_t>(
      options_.trial_channel, [this](const orbed::alignment_trial_t& msg, const std::string&, int64_t) {
        if (auto state = HandleTrial(msg)) Publish(options_.registration_channel, *state);
      });
  Subscribe<orbed::landmark_request_t>(
      options_.landmark_request_channel,
      [this](const orbed::landmark_request_t& msg, const std::string&, int64_t) {
        Publish(options_.landmark_channel, service_.HandleLandmarkRequest(msg));
      });
  Subscribe<orbed::misalignment_request_t>(
      options_.misalignment_request_channel,
      [this](const orbed::misalignment_request_t& msg, const std::string&, int64_t) {
        Publish(options_.misalignment_channel, service_.HandleMisalignmentRequest(msg));
      });
  if (options_.state_period_s > 0.0) {
    AddTimer(options_.state_period_s, [this]() {
      if (auto state = service_.PeriodicState()) Publish(options_.registration_channel, *state);
    });
  }
  ORBED_LOG(kInfo) << "serving " << options_.trial_channel << " -> " << options_.registration_channel;
}

std::optional<orbed::registration_t> RegistrationServer::HandleSessionControl(
    const orbed::session_control_t& msg) {
  return journal_ ? journal_->HandleSessionControl(msg) : service_.HandleSessionControl(msg);
}

std::optional<orbed::registration_t> RegistrationServer::HandleTrial(const orbed::alignment_trial_t& msg) {
  return journal_ ? journal_->HandleTrial(msg) : service_.HandleTrial(msg);
}

}  // namespace orbed::registration
