#pragma once
/// @file
/// The launcher-deputy protocol (contract changes 9 and 10), defined once for both sides.
///
///   DEPUTY_COMMAND (deputy_command_t): the launcher → one deputy, the whole wanted state of the
///     processes it placed on that deputy's host, every kDeputyPeriodS and at once on a change.
///   DEPUTY_STATUS (deputy_status_t): each deputy → everyone, the state of those processes, every
///     kDeputyPeriodS and at once on a change.
///
/// Both are level-triggered (each message is the whole state), so a lost datagram costs one
/// period: a process is started when the wanted instance number exceeds the deputy's, stopped
/// when `run` is false, and never started twice for one instance.
///
/// Checks (the reason names the field; a deputy or launcher counts it under
/// "<channel>/invalid" and keeps running):
///   deputy_command_t: launcher and deputy names 1..kMaxDeputyName bytes; launcher_start_utime
///     > 0; at most
///     kMaxDeputyProcesses processes with distinct names (1..kMaxDeputyName bytes, no '/' or
///     space); instance >= 1; argc 1..kMaxArgc equal to argv's length, argv[0] not empty, each
///     argument at most kMaxArgBytes; num_env at most kMaxEnv equal to both arrays' lengths, keys
///     1..kMaxDeputyName bytes without '='; stop_signal one of SIGINT, SIGTERM, SIGHUP, SIGQUIT,
///     SIGUSR1, SIGUSR2, SIGKILL; stop_timeout_s finite in [0, kMaxStopTimeoutS]; run_dir empty or
///     one path component (1..kMaxDeputyName bytes, no '/', not "." or "..").
///   deputy_status_t: deputy name 1..kMaxDeputyName bytes, launcher at most that; at most
///     kMaxDeputyProcesses children, num_children equal to the array's length; each child's name
///     1..kMaxDeputyName bytes, instance >= 1, pid >= 0, state in range; num_last_lines
///     0..kMaxLastLines equal to the array's length, each line at most kMaxLastLineBytes.
///
/// Threading: pure functions.

#include <cstddef>
#include <string>

#include <orbed/deputy_command_t.hpp>
#include <orbed/deputy_status_t.hpp>

namespace orbed::launcher {

inline constexpr double kDeputyPeriodS = 0.2;
inline constexpr size_t kMaxDeputyName = 256;
inline constexpr size_t kMaxDeputyProcesses = 64;
inline constexpr size_t kMaxArgc = 256;
inline constexpr size_t kMaxArgBytes = 4096;
inline constexpr size_t kMaxEnv = 256;
inline constexpr double kMaxStopTimeoutS = 3600;
/// A deputy's report of a child carries its last lines of output: at most this many, each cut to
/// at most this many bytes.
inline constexpr size_t kMaxLastLines = 5;
inline constexpr size_t kMaxLastLineBytes = 512;
/// The launch file's variable that a deputy expands to its own run folder (deputy_command_t.run_dir).
inline constexpr char kLogDirVariable[] = "${ORBED_LOG_DIR}";

/// "" when the command is well formed, else why not.
std::string CheckDeputyCommand(const orbed::deputy_command_t& msg);
/// "" when the status is well formed, else why not.
std::string CheckDeputyStatus(const orbed::deputy_status_t& msg);

/// `text` with every kLogDirVariable replaced by `dir`.
std::string ExpandLogDir(const std::string& text, const std::string& dir);

/// Whether `run_dir` may name a run folder: one path component, 1..kMaxDeputyName bytes.
bool RunDirOk(const std::string& run_dir);

/// "exited with code N" or "killed by signal <name>" (as Child::DescribeExit).
std::string DescribeExit(int exit_code, int term_signal);

}  // namespace orbed::launcher
