#include "procs/common/flags.h"

#include <cstdlib>
#include <regex>

#include "procs/common/log.h"

namespace orbed {

CommonFlags::CommonFlags(std::string default_name)
    : lcm_url(DefaultLcmUrl()), name(std::move(default_name)) {}

std::string DefaultLcmUrl() {
  const char* env = std::getenv("ORBED_LCM_URL");
  if (env != nullptr && env[0] != '\0') return env;
  return kDefaultLcmUrl;
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
  app->add_option("--lcm-url", flags->lcm_url,
                  "LCM provider URL (default: $ORBED_LCM_URL, else " + std::string(kDefaultLcmUrl) + ")")
      ->capture_default_str();
  app->add_option("--name", flags->name, "Process name on PROCESS_STATUS and in log lines")
      ->capture_default_str();
  app->add_option("--seed", flags->seed, "Seed of every random generator in this process")
      ->capture_default_str();
  app->add_option("--duration-s", flags->duration_s,
                  "Stop cleanly after this many seconds (0: run until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--log-level", flags->log_level, "debug | info | warn | error")
      ->check(CLI::IsMember({"debug", "info", "warn", "error"}))
      ->capture_default_str();
}

void ApplyCommonFlags(const CommonFlags& flags) {
  LogLevel level;
  if (!ParseLogLevel(flags.log_level, &level)) {
    throw CLI::ValidationError("--log-level", "expected debug, info, warn or error");
  }
  SetLogName(flags.name);
  SetLogLevel(level);
}

std::optional<int> ParseCommandLine(CLI::App* app, const CommonFlags& flags, int argc,
                                    const char* const* argv, std::ostream& out, std::ostream& err) {
  try {
    app->parse(argc, argv);
    ApplyCommonFlags(flags);
  } catch (const CLI::ParseError& e) {
    return app->exit(e, out, err);
  }
  return std::nullopt;
}

}  // namespace orbed
