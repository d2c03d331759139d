#pragma once
/// @file
/// The flags every orbed process shares, on CLI11:
///   --lcm-url URL      LCM provider URL (default: $ORBED_LCM_URL, else udpm://239.255.76.67:7667?ttl=0)
///   --name NAME        process name on PROCESS_STATUS and in log lines
///   --seed N           seed of every random generator in the process
///   --duration-s S   stop cleanly after S seconds (0 = run until SIGINT/SIGTERM)
///   --log-level L      debug | info | warn | error
///   --chaos SPEC       fault injection on received datagrams (default: $ORBED_CHAOS; chaos.h)
/// and, for the processes that can follow the sim clock (AddSimTimeFlag):
///   --sim-time         timers, timeouts and stamps on SIM_CLOCK
/// Usage in a thin main:
///   CLI::App app{"what it does"};
///   orbed::CommonFlags common("orbed-foo");
///   orbed::AddCommonFlags(&app, &common);
///   ... process-specific flags ...
///   CLI11_PARSE(app, argc, argv);   // --help → exit 0, bad flag → exit != 0
///   orbed::ApplyCommonFlags(common);

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>

#include "base/command_line.h"  // CLI::App, declared only

namespace orbed {

/// Multicast group and port of the testbed (LCM's own default group, ttl=0: never leaves the host).
inline constexpr char kDefaultLcmUrl[] = "udpm://239.255.76.67:7667?ttl=0";

struct CommonFlags {
  explicit CommonFlags(std::string default_name);
  std::string lcm_url;
  std::string name;
  uint64_t seed = 1;
  double duration_s = 0.0;
  std::string log_level = "info";
  /// Fault injection spec (runtime/chaos.h); "" = none.
  std::string chaos;
  /// Follow the sim clock (SIM_CLOCK, runtime/sim_clock.h) instead of the monotonic and wall
  /// clocks (Process, process.h).
  bool sim_time = false;
  /// With sim_time, the arm whose clock to follow (one of several): SIM_CLOCK_<ARM> in,
  /// lockstep answers on SIM_CLOCK_ACK_<ARM> (channels::ForArm); "" = the single arm's SIM_CLOCK.
  /// Set by the processes that take --arm.
  std::string sim_clock_arm;
};

/// The URL a process uses when --lcm-url is not given.
std::string DefaultLcmUrl();

/// Adds `url`'s query parameter recv_buf_size=bytes (replacing one that is there), for processes
/// that subscribe to large messages (images). LCM's default UDP receive buffer drops ~1 MB
/// messages outright. Other providers (memq://, file://) are returned unchanged.
std::string WithRecvBufSize(const std::string& url, int64_t bytes);

/// Adds the flags above and --version (base/command_line.h).
void AddCommonFlags(CLI::App* app, CommonFlags* flags);
/// Adds --sim-time for a process whose timers may follow the sim clock. The sim
/// (the clock's source), the logger, the launcher and the monitor do not take it.
void AddSimTimeFlag(CLI::App* app, CommonFlags* flags);

/// Adds `flag` (--headset or --arm) naming one of several headsets or arms, checked against
/// channels::IsInstanceName; the process suffixes its channels with it (channels::ForHeadset,
/// channels::ForArm). `help` says which.
void AddInstanceFlag(CLI::App* app, const std::string& flag, std::string* name, const std::string& help);

/// Sets the log name and level; throws CLI::ValidationError on a bad level or chaos spec.
void ApplyCommonFlags(const CommonFlags& flags);

/// The start of every command line's Run…(): parses `argv` into `app` (AddCommonFlags called on
/// it) and applies the common flags. Returns std::nullopt to go on, else the exit code to return
/// now: 0 after --help or --version (on `out`), kExitUsage (2) after a bad flag or value (the
/// message on `err`; base/command_line.h).
std::optional<int> ParseCommandLine(CLI::App* app, const CommonFlags& flags, int argc,
                                    const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed
