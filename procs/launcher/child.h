#pragma once
/// @file
/// One child process of orbed-launch: fork/exec in its own process group (so a terminal's Ctrl-C
/// reaches only the launcher, which then stops children in order) with PR_SET_PDEATHSIG = SIGKILL,
/// so it dies with the launcher (or deputy) that started it when that one is killed outright:
/// nobody is left to stop it in order or to escalate a stop that hangs, and what the processes
/// keep (logs, state files, journals) is written to survive a SIGKILL. Only the child itself:
/// processes it starts in turn are not covered (the testbed's processes start none). stdout and
/// stderr merged into a pipe that the launcher reads and re-emits line by line with the child's
/// name in front.
///
/// Threading: not thread-safe; used from the launcher's loop thread only.

#include <sys/types.h>

#include <map>
#include <string>
#include <vector>

namespace orbed::launcher {

/// What the launcher needs of a child, whether it runs here (Child) or on another host, started by
/// a deputy (RemoteChild, deputy_link.h).
class ChildHandle {
 public:
  virtual ~ChildHandle() = default;
  virtual bool Start(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env,
                     const std::string& search_dir, std::string* error) = 0;
  virtual bool Poll() = 0;
  virtual bool running() const = 0;
  virtual pid_t pid() const = 0;
  virtual int exit_code() const = 0;
  virtual int term_signal() const = 0;
  virtual std::string DescribeExit() const = 0;
  virtual void Signal(int signal) = 0;
  virtual void Drain(const std::string& prefix, bool final = false) = 0;
  /// The last line it printed ("" when none; on another host, the last line its deputy reported with
  /// its exit).
  virtual std::string last_line() const { return ""; }
};

class Child : public ChildHandle {
 public:
  Child() = default;
  ~Child() override;
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// Starts `argv[0]` (resolved: a path with '/' as is, else in `search_dir` if it is there, else
  /// PATH) with the launcher's environment plus `env`. Returns false with *error set when it
  /// cannot start (fork failure or a missing executable, detected before fork).
  bool Start(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env,
             const std::string& search_dir, std::string* error) override;

  /// Non-blocking: reaps the child if it exited. Returns true once it has exited.
  bool Poll() override;
  bool running() const override { return pid_ > 0 && !exited_; }
  pid_t pid() const override { return pid_; }
  /// Valid after Poll() returned true.
  int exit_code() const override { return exit_code_; }      // -1 when killed by a signal
  int term_signal() const override { return term_signal_; }  // 0 unless killed by a signal
  std::string DescribeExit() const override;

  /// Sends `signal` to the child's process group.
  void Signal(int signal) override;

  /// Reads what the child printed (non-blocking) and writes complete lines to stdout as
  /// "<prefix><line>" (and, after CopyLinesTo, appends each line without the prefix there). At
  /// exit the rest is flushed with Drain(true).
  void Drain(const std::string& prefix, bool final = false) override;
  /// Also keep every line the child prints in `*lines` (tests read a child's output).
  void CopyLinesTo(std::vector<std::string>* lines) { copy_ = lines; }
  std::string last_line() const override { return last_line_; }

 private:
  pid_t pid_ = -1;
  int output_fd_ = -1;
  bool exited_ = false;
  int exit_code_ = 0;
  int term_signal_ = 0;
  std::string partial_line_;
  std::string last_line_;
  std::vector<std::string>* copy_ = nullptr;
};

/// Resolves an executable name as Child::Start does; "" if not found.
std::string ResolveExecutable(const std::string& command, const std::string& search_dir);

}  // namespace orbed::launcher
