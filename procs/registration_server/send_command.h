#pragma once
/// @file
/// `orbed-registration send`: feeds a trial file (trial_file.h) to a running orbed-registration
/// over LCM as one session — SESSION_CONTROL START, one ALIGNMENT_TRIAL per line, then COMPUTE —
/// and prints the server's answer (the REGISTRATION with reason COMPUTE for that session) in the
/// JSON shape of `orbed-registration mean --json`. For users who have poses in a file and want
/// them in a live testbed (and a check that the server agrees with the offline mean).
///
/// Exit codes: 0 answer received; 2 bad input; 1 no answer within the timeout or LCM unavailable.
///
/// Threading: single-threaded; blocks until the answer or the timeout.

#include <ostream>
#include <string>

namespace orbed::registration {

struct SendCommandOptions {
  std::string input_path;  ///< trial file; "-" reads standard input
  std::string lcm_url;
  std::string session_id = "orbed-registration-send";
  bool robust = false;
  double timeout_s = 5.0;
  std::string session_control_channel = "SESSION_CONTROL";
  std::string trial_channel = "ALIGNMENT_TRIAL";
  std::string registration_channel = "REGISTRATION";
};

int RunSendCommand(const SendCommandOptions& options, std::ostream& out, std::ostream& err);

}  // namespace orbed::registration
