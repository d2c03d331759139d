#include "procs/registration_server/send_command.h"

#include <chrono>
#include <fstream>
#include <iostream>

#include <lcm/lcm-cpp.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/session_control_t.hpp>

#include "base/json.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/registration_server/trial_file.h"

namespace orbed::registration {
namespace {

struct AnswerWaiter {
  std::string session_id;
  bool got = false;
  orbed::registration_t answer;
  void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::registration_t* msg) {
    if (msg->session_id == session_id && msg->reason == orbed::registration_t::REASON_COMPUTE) {
      answer = *msg;
      got = true;
    }
  }
};

std::string AnswerJson(const orbed::registration_t& r) {
  JsonWriter json;
  json.BeginObject();
  json.Key("rotation_wxyz")
      .Array(std::vector<double>(r.X_WV_mean.quaternion_wxyz, r.X_WV_mean.quaternion_wxyz + 4));
  json.Key("translation_m").Array(std::vector<double>(r.X_WV_mean.position_m, r.X_WV_mean.position_m + 3));
  json.Key("converged").Bool(r.converged);
  json.Key("unique").Bool(r.unique);
  json.Key("iterations").Int(r.iterations);
  json.Key("n_used").Int(r.num_used);
  json.Key("rejected").Array(std::vector<int>(r.rejected_indices.begin(), r.rejected_indices.end()));
  json.Key("rotation_rms_deg").Number(r.rotation_rms_deg);
  json.Key("translation_rms_m").Number(r.translation_rms_m);
  json.EndObject();
  return json.str();
}

}  // namespace

int RunSendCommand(const SendCommandOptions& options, std::ostream& out, std::ostream& err) {
  std::ifstream file;
  if (options.input_path != "-") {
    file.open(options.input_path);
    if (!file) {
      err << options.input_path << ": error: cannot read the trial file\n";
      return 2;
    }
  }
  const TrialFile trials = ParseTrialFile(options.input_path == "-" ? std::cin : file);
  if (!trials.ok) {
    err << options.input_path << ":" << trials.error_line << ": error: " << trials.error << "\n";
    return 2;
  }
  if (trials.quat_WV.empty()) {
    err << options.input_path << ": error: no trials in the file\n";
    return 2;
  }
  lcm::LCM lcm(options.lcm_url);
  if (!lcm.good()) {
    err << "orbed-registration send: cannot open LCM at '" << options.lcm_url << "'\n";
    return 1;
  }
  AnswerWaiter waiter;
  waiter.session_id = options.session_id;
  lcm.subscribe(options.registration_channel, &AnswerWaiter::On, &waiter);

  const int64_t t0 = NowMicros();
  orbed::session_control_t control{};
  control.utime = t0;
  control.session_id = options.session_id;
  control.command = orbed::session_control_t::START;
  control.display_mode = orbed::alignment_trial_t::MODE_AR;
  control.method =
      options.robust ? orbed::registration_t::METHOD_ROBUST : orbed::registration_t::METHOD_KARCHER;
  lcm.publish(options.session_control_channel, &control);
  for (size_t i = 0; i < trials.quat_WV.size(); ++i) {
    orbed::alignment_trial_t trial{};
    trial.utime = t0 + 1 + static_cast<int64_t>(i);
    trial.session_id = options.session_id;
    trial.trial_index = static_cast<int32_t>(i);
    trial.display_mode = orbed::alignment_trial_t::MODE_AR;
    // The file's numbers as they are (no round trip through a matrix), so that the server sees
    // exactly what the offline mean sees.
    QuaternionToWxyz(trials.quat_WV[i], trial.X_WV.quaternion_wxyz);
    FromVector3(trials.p_WV[i], trial.X_WV.position_m);
    trial.user_id = "file:" + options.input_path + ":" + std::to_string(trials.line[i]);
    lcm.publish(options.trial_channel, &trial);
  }
  control.utime = t0 + 1 + static_cast<int64_t>(trials.quat_WV.size());
  control.command = orbed::session_control_t::COMPUTE;
  lcm.publish(options.session_control_channel, &control);

  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<int64_t>(options.timeout_s * 1000));
  while (!waiter.got && std::chrono::steady_clock::now() < deadline) lcm.handleTimeout(50);
  if (!waiter.got) {
    err << "orbed-registration send: no REGISTRATION for session '" << options.session_id << "' within "
        << options.timeout_s << " s (is orbed-registration running on " << options.lcm_url << "?)\n";
    return 1;
  }
  // UDP may lose a trial; a mean of fewer trials than the file holds must not pass silently.
  if (waiter.answer.num_trials != static_cast<int32_t>(trials.quat_WV.size())) {
    err << "orbed-registration send: the server holds " << waiter.answer.num_trials << " trials of session '"
        << options.session_id << "', the file " << trials.quat_WV.size()
        << " (messages lost, or another sender on the session?)\n";
    return 1;
  }
  out << AnswerJson(waiter.answer) << "\n";
  return 0;
}

}  // namespace orbed::registration
