#pragma once
/// @file
/// Helpers for benchmarks that measure whole orbed processes: start one (stdout to /dev/null),
/// stop it with SIGINT and read its CPU time and peak RSS from wait4. Header-only; used from the
/// benchmark's main thread.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace orbed::bench {

struct Usage {
  double cpu_s = 0;        ///< user + system [s]
  double peak_rss_mb = 0;  ///< maximum resident set size [MiB]
  int exit_code = -1;      ///< -1 when killed by a signal
};

/// build/bin, from ORBED_BIN_DIR (set by `scripts/orbed bench`) or beside build/bench/<exe>.
inline std::string BinDir() {
  if (const char* dir = std::getenv("ORBED_BIN_DIR")) return dir;
  return (std::filesystem::read_symlink("/proc/self/exe").parent_path().parent_path() / "bin").string();
}

/// fork + execv (argv[0] is a path); the child's stdout goes to /dev/null.
inline pid_t Spawn(const std::vector<std::string>& argv) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    if (std::freopen("/dev/null", "w", stdout) == nullptr) _exit(126);
    execv(args[0], args.data());
    _exit(127);
  }
  return pid;
}

/// SIGINT, wait, and the child's resource usage.
inline Usage StopAndMeasure(pid_t pid) {
  kill(pid, SIGINT);
  int status = 0;
  rusage usage{};
  wait4(pid, &status, 0, &usage);
  Usage u;
  u.cpu_s = usage.ru_utime.tv_sec + usage.ru_utime.tv_usec * 1e-6 + usage.ru_stime.tv_sec +
            usage.ru_stime.tv_usec * 1e-6;
  u.peak_rss_mb = usage.ru_maxrss / 1024.0;
  u.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return u;
}

}  // namespace orbed::bench
