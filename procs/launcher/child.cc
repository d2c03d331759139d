#include "procs/launcher/child.h"

#include "procs/launcher/deputy_protocol.h"
#include "procs/launcher/launch_file.h"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace orbed::launcher {
namespace {

bool IsExecutable(const std::string& path) { return access(path.c_str(), X_OK) == 0; }

}  // namespace

std::string ResolveExecutable(const std::string& command, const std::string& search_dir) {
  if (command.find('/') != std::string::npos) return IsExecutable(command) ? command : "";
  if (!search_dir.empty() && IsExecutable(search_dir + "/" + command)) {
    return search_dir + "/" + command;
  }
  const char* path_env = std::getenv("PATH");
  std::stringstream path(path_env ? path_env : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(path, dir, ':')) {
    if (!dir.empty() && IsExecutable(dir + "/" + command)) return dir + "/" + command;
  }
  return "";
}

Child::~Child() {
  if (output_fd_ >= 0) close(output_fd_);
}

bool Child::Start(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env,
                  const std::string& search_dir, std::string* error) {
  const std::string executable = ResolveExecutable(argv.at(0), search_dir);
  if (executable.empty()) {
    *error = "cannot find executable '" + argv[0] + "' (looked in " +
             (search_dir.empty() ? "" : search_dir + " and ") + "PATH)";
    return false;
  }
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    *error = std::string("pipe failed: ") + std::strerror(errno);
    return false;
  }
  // Everything the child needs is prepared before fork: after fork only async-signal-safe calls.
  std::map<std::string, std::string> full_env = CurrentEnvironment();
  for (const auto& [key, value] : env) full_env[key] = value;
  std::vector<std::string> env_strings;
  for (const auto& [key, value] : full_env) env_strings.push_back(key + "=" + value);
  std::vector<char*> c_envp;
  for (std::string& entry : env_strings) c_envp.push_back(entry.data());
  c_envp.push_back(nullptr);
  std::vector<char*> c_argv;
  for (const std::string& arg : argv) c_argv.push_back(const_cast<char*>(arg.c_str()));
  c_argv.push_back(nullptr);
  const pid_t parent = getpid();

  // Signals are blocked across fork: one sent to the new child before it has reset its
  // dispositions would otherwise reach the launcher's handlers in the child and be lost (a stop
  // right after a start). The child unblocks them once they are back at their defaults.
  sigset_t all, previous;
  sigfillset(&all);
  sigprocmask(SIG_SETMASK, &all, &previous);
  const pid_t pid = fork();
  if (pid != 0) sigprocmask(SIG_SETMASK, &previous, nullptr);
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    *error = std::string("fork failed: ") + std::strerror(errno);
    return false;
  }
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // the launcher died between fork and prctl
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    int devnull = open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, STDIN_FILENO);
    // Default signal dispositions, then an empty mask for the new program (a signal sent meanwhile
    // is delivered now, with its default action).
    for (int s = 1; s < NSIG; ++s) {
      if (s != SIGKILL && s != SIGSTOP) signal(s, SIG_DFL);
    }
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    execve(executable.c_str(), c_argv.data(), c_envp.data());
    const char* message = "orbed-launch: exec failed\n";
    (void)!write(STDERR_FILENO, message, std::strlen(message));
    _exit(127);
  }
  setpgid(pid, pid);  // also from the parent, so signalling the group works at once
  close(fds[1]);
  output_fd_ = fds[0];
  fcntl(output_fd_, F_SETFL, fcntl(output_fd_, F_GETFL) | O_NONBLOCK);
  pid_ = pid;
  exited_ = false;
  exit_code_ = 0;
  term_signal_ = 0;
  partial_line_.clear();
  last_line_.clear();
  return true;
}

bool Child::Poll() {
  if (pid_ <= 0) return true;
  if (exited_) return true;
  int status = 0;
  const pid_t result = waitpid(pid_, &status, WNOHANG);
  if (result == pid_) {
    exited_ = true;
    if (WIFEXITED(status)) {
      exit_code_ = WEXITSTATUS(status);
    } else if (WIFSIGNALED(status)) {
      exit_code_ = -1;
      term_signal_ = WTERMSIG(status);
    }
  }
  return exited_;
}

std::string Child::DescribeExit() const { return launcher::DescribeExit(exit_code_, term_signal_); }

void Child::Signal(int signal) {
  if (running()) kill(-pid_, signal);
}

void Child::Drain(const std::string& prefix, bool final) {
  if (output_fd_ < 0) return;
  char buffer[4096];
  for (;;) {
    const ssize_t n = read(output_fd_, buffer, sizeof(buffer));
    if (n > 0) {
      partial_line_.append(buffer, static_cast<size_t>(n));
      continue;
    }
    if (n == 0) {  // every writer closed: the child (and its children) are gone
      close(output_fd_);
      output_fd_ = -1;
    }
    break;  // EAGAIN or EOF
  }
  size_t start = 0;
  for (size_t newline; (newline = partial_line_.find('\n', start)) != std::string::npos;
       start = newline + 1) {
    last_line_ = partial_line_.substr(start, newline - start);
    std::fprintf(stdout, "%s%s\n", prefix.c_str(), last_line_.c_str());
    if (copy_ != nullptr) copy_->push_back(last_line_);
  }
  partial_line_.erase(0, start);
  if ((final || output_fd_ < 0) && !partial_line_.empty()) {
    last_line_ = partial_line_;
    std::fprintf(stdout, "%s%s\n", prefix.c_str(), last_line_.c_str());
    if (copy_ != nullptr) copy_->push_back(last_line_);
    partial_line_.clear();
  }
  std::fflush(stdout);
}

}  // namespace orbed::launcher
