#include "runtime/flags.h"

#include <CLI/CLI.hpp>

#include <cstdlib>
#include <regex>

#include "base/log.h"
#include "lcmtypes/contract/channels.h"
#include "runtime/chaos.h"

namespace orbed {

namespace {

std::string Environment(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr ? value : "";
}

}  // namespace

CommonFlags::CommonFlags(std::string default_name)
    : lcm_url(DefaultLcmUrl()), name(std::move(default_name)), chaos(Environment("ORBED_CHAOS")) {}

std::string DefaultLcmUrl() {
  const std::string env = Environment("ORBED_LCM_URL");
  return env.empty() ? kDefaultLcmUrl : env;
}

std::string WithRecvBufSize(const std::string& url, int64_t bytes) {
  if (url.rfind("udpm://", 0) != 0) return url;  // only the UDP provider has a receive buffer
  static const std::regex kExisting("([?&])recv_buf_size=[0-9]+");
  const std::string param = "recv_buf_size=" + std::to_string(bytes);
  if (std::regex_search(url, kExisting)) {
    return std::regex_replace(url, kExisting, "$1" + param);
  }
  return url + (url.find('?') == std::string::npos ? "?" : "&") + param;
}

void AddCommonFlags(CLI::App* app, CommonFlags* flags) {
  AddVersionFlag(app);
  app->add_option("--lcm-url", flags->lcm_url,
                  "LCM provider URL (default: $ORBED_LCM_URL, else " + std::string(kDefaultLcmUrl) + ")")
      ->capture_default_str();
  app->add_option("--name", flags->name, "Process name on PROCESS_STATUS and in log lines")
      ->capture_default_str();
  app->add_option("--seed", flags->seed, "Seed of every random generator in this process")
      ->capture_default_str();
  app->add_option("--duration-s", flags->duration_s,
                  "Stop cleanly after this many seconds (0: run until SIGINT/SIGTERM)")
      ->check(NonNegativeNumber())
      ->capture_default_str();
  app->add_option("--log-level", flags->log_level, "debug | info | warn | error")
      ->check(CLI::IsMember({"debug", "info", "warn", "error"}))
      ->capture_default_str();
  app->add_option("--chaos", flags->chaos,
                  "Fault injection on received datagrams, e.g. drop=0.1,dup=0.05,delay_ms=30,reorder=0.05,"
                  "seed=1,channels=REGEX (default: $ORBED_CHAOS; none when empty)");
}

void AddSimTimeFlag(CLI::App* app, CommonFlags* flags) {
  app->add_flag(
      "--sim-time", flags->sim_time,
      "Run timers, timeouts and stamps on the sim's clock (SIM_CLOCK from orbed-iiwa-sim, which may "
      "run faster than real time) instead of the wall clock, answering its lockstep rounds on "
      "SIM_CLOCK_ACK");
}

void AddInstanceFlag(CLI::App* app, const std::string& flag, std::string* name, const std::string& help) {
  app->add_option(flag, *name, help)
      ->check(CLI::Validator(
          [](std::string& value) {
            return channels::IsInstanceName(value) ? std::string()
                                                   : std::string("expected ") + channels::kInstanceNameRule;
          },
          "NAME"));
}

void ApplyCommonFlags(const CommonFlags& flags) {
  LogLevel level;
  if (!ParseLogLevel(flags.log_level, &level)) {
    throw CLI::ValidationError("--log-level", "expected debug, info, warn or error");
  }
  try {
    ParseChaosSpec(flags.chaos);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--chaos", e.what());
  }
  SetLogName(flags.name);
  SetLogLevel(level);
}

std::optional<int> ParseCommandLine(CLI::App* app, const CommonFlags& flags, int argc,
                                    const char* const* argv, std::ostream& out, std::ostream& err) {
  if (const auto code = ParseArguments(app, argc, argv, out, err)) return code;
  try {
    ApplyCommonFlags(flags);
  } catch (const CLI::ParseError& e) {
    app->exit(e, out, err);
    return kExitUsage;
  }
  return std::nullopt;
}

}  // namespace orbed
