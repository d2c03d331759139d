#include "procs/monitor/monitor.h"

#include <cstdio>
#include <iostream>

#include "base/format.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::monitor {
namespace {

const char* StateName(int8_t state) {
  switch (state) {
    case orbed::process_status_t::STATE_STARTING:
      return "starting";
    case orbed::process_status_t::STATE_RUNNING:
      return "running";
    case orbed::process_status_t::STATE_STOPPING:
      return "stopping";
    case orbed::process_status_t::STATE_FAILED:
      return "FAILED";
  }
  return "?";
}

// Bounds that keep a flood of made-up names from growing the table without limit.
constexpr size_t kMaxProcesses = 256;
constexpr size_t kMaxNameLength = 64;

}  // namespace

Monitor::Monitor(const CommonFlags& flags, MonitorOptions options) : options_(options), process_(flags) {
  process_.Subscribe<orbed::process_status_t>(
      channels::kProcessStatus,
      [this](const orbed::process_status_t& msg, const std::string& channel, int64_t recv_utime) {
        const std::string error =
            FirstError({CheckEnum(msg.state, 0, 3, "state"),
                        msg.name.empty() || msg.name.size() > kMaxNameLength
                            ? "name of " + std::to_string(msg.name.size()) + " characters, expected 1.." +
                                  std::to_string(kMaxNameLength)
                            : "",
                        msg.host.size() > kMaxNameLength
                            ? "host of " + std::to_string(msg.host.size()) +
                                  " characters, expected at most " + std::to_string(kMaxNameLength)
                            : ""});
        if (!error.empty()) {
          process_.Reject(channel + "/field", error);
          return;
        }
        if (processes_.count(msg.name) == 0 && processes_.size() >= kMaxProcesses) {
          process_.Reject(channel + "/too_many", "more than " + std::to_string(kMaxProcesses) +
                                                     " process names; ignoring '" + msg.name + "'");
          return;
        }
        Seen& seen = processes_[msg.name];
        if (seen.silent && options_.out != nullptr) {
          *options_.out << EscapeText(msg.name) << " on " << EscapeText(msg.host) << ": heard again after "
                        << Fixed((recv_utime - seen.recv_utime) * 1e-6, 1) << " s\n"
                        << std::flush;
        }
        seen = Seen{msg, recv_utime, false};
      });
  process_.Subscribe<orbed::logger_status_t>(
      channels::kLoggerStatus, [this](const orbed::logger_status_t& msg, const std::string&, int64_t) {
        logger_ = msg;
        have_logger_ = true;
      });
  process_.AddTimer(options_.print_period_s, [this] {
    if (options_.out != nullptr) *options_.out << Table(NowMicros()) << std::flush;
  });
  process_.AddWallPoll(0.1, [this] {
    const std::string lines = NewlySilent(NowMicros());
    if (!lines.empty() && options_.out != nullptr) *options_.out << lines << std::flush;
  });
}

std::string Monitor::NewlySilent(int64_t now_utime) {
  std::string out;
  for (auto& [name, seen] : processes_) {
    const double age_s = (now_utime - seen.recv_utime) * 1e-6;
    if (seen.silent || age_s <= options_.silent_after_s) continue;
    seen.silent = true;
    if (seen.status.state == orbed::process_status_t::STATE_STOPPING) {
      out += EscapeText(name) + " on " + EscapeText(seen.status.host) +
             ": stopped (its last heartbeat said so)\n";
      continue;
    }
    out += EscapeText(name) + " on " + EscapeText(seen.status.host) + ": SILENT (no heartbeat for " +
           Fixed(age_s, 1) + " s)\n";
  }
  return out;
}

std::string Monitor::Table(int64_t now_utime) const {
  std::string out =
      "process               host          state     uptime_s      in       out  rejected   dropped  last "
      "error\n";
  char line[512];
  for (const auto& [name, seen] : processes_) {
    const orbed::process_status_t& s = seen.status;
    const double age_s = (now_utime - seen.recv_utime) * 1e-6;
    const std::string state = age_s > options_.silent_after_s ? "SILENT" : StateName(s.state);
    // Names and errors come from the bus: escaped before they reach a terminal.
    std::snprintf(line, sizeof(line), "%-20s  %-12s  %-8s  %8.1f  %7lld  %8lld  %8lld  %8lld  %s\n",
                  EscapeText(name).c_str(), EscapeText(s.host.substr(0, 12)).c_str(), state.c_str(),
                  s.uptime_s, static_cast<long long>(s.messages_in), static_cast<long long>(s.messages_out),
                  static_cast<long long>(s.rejected_inputs), static_cast<long long>(s.dropped),
                  EscapeText(s.last_error.substr(0, 60)).c_str());
    out += line;
  }
  if (have_logger_) {
    std::snprintf(line, sizeof(line), "log: %s  events %lld  bytes %lld  drops %lld  queue %d/%d\n",
                  EscapeText(logger_.file).c_str(), static_cast<long long>(logger_.events_written),
                  static_cast<long long>(logger_.bytes_written), static_cast<long long>(logger_.drops),
                  logger_.queue_depth, logger_.queue_capacity);
    out += line;
  }
  return out;
}

}  // namespace orbed::monitor
