#include "procs/launcher/deputy_link.h"

#include <csignal>
#include <cstdio>

#include <orbed/deputy_command_t.hpp>

#include "base/format.h"
#include "base/log.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/launcher/deputy_protocol.h"

namespace orbed::launcher {
namespace {

double SecondsBetween(DeputyLink::Clock::time_point a, DeputyLink::Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// A child on another host, as its deputy reports it.
class RemoteChild : public ChildHandle {
 public:
  RemoteChild(DeputyLink* link, DeputyLink::Slot* slot) : link_(link), slot_(slot) {}

  bool Start(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env,
             const std::string&, std::string*) override {
    ++slot_->instance;
    exited_ = false;
    slot_->run = true;
    slot_->argv = argv;
    slot_->env = env;
    slot_->stop_signal = slot_->spec_stop_signal;
    link_->Changed(slot_->deputy);
    return true;
  }
  // As Child: running() holds until Poll() has seen the exit (the deputy's report of it).
  bool Poll() override {
    if (!exited_ && Reported()) {
      exited_ = slot_->state == orbed::deputy_child_t::STATE_EXITED ||
                slot_->state == orbed::deputy_child_t::STATE_FAILED_TO_START;
      // Gone is gone: a deputy that restarts must not start this instance again.
      if (exited_ && slot_->run) {
        slot_->run = false;
        link_->Changed(slot_->deputy);
      }
    }
    return !running();
  }
  bool running() const override { return slot_->instance > 0 && !exited_; }
  pid_t pid() const override { return Reported() ? slot_->pid : 0; }
  int exit_code() const override { return Reported() ? slot_->exit_code : 0; }
  int term_signal() const override { return Reported() ? slot_->term_signal : 0; }
  std::string DescribeExit() const override {
    const std::string where = " on " + slot_->deputy;
    if (Reported() && slot_->state == orbed::deputy_child_t::STATE_FAILED_TO_START) {
      return "could not start" + where + ": " + slot_->detail;
    }
    return launcher::DescribeExit(exit_code(), term_signal()) + where;
  }
  // The last of the lines its deputy reported with its exit.
  std::string last_line() const override {
    return Reported() && !slot_->last_lines.empty() ? slot_->last_lines.back() : "";
  }
  void Signal(int signal) override {
    if (!slot_->run && slot_->stop_signal == signal) return;
    slot_->run = false;
    slot_->stop_signal = signal;
    link_->Changed(slot_->deputy);
  }
  // The deputy prints the output on its host; at an exit other than code 0, its last lines are
  // printed here too.
  void Drain(const std::string& prefix, bool final) override {
    if (!final || !Reported() || (exit_code() == 0 && term_signal() == 0)) return;
    for (const std::string& line : slot_->last_lines) {
      std::printf("%s[%s] %s\n", prefix.c_str(), slot_->deputy.c_str(), EscapeText(line).c_str());
    }
    std::fflush(stdout);
  }

 private:
  bool Reported() const { return slot_->reported_instance == slot_->instance; }
  DeputyLink* link_;
  DeputyLink::Slot* slot_;
  bool exited_ = false;
};

}  // namespace

DeputyLink::DeputyLink(Process* process, std::string launcher_id, int64_t start_utime, std::string run_dir)
    : process_(process),
      launcher_id_(std::move(launcher_id)),
      start_utime_(start_utime),
      run_dir_(std::move(run_dir)) {
  process_->Subscribe<orbed::deputy_status_t>(channels::kDeputyStatus,
                                              [this](const orbed::deputy_status_t& status, const std::string&,
                                                     int64_t recv_utime) { OnStatus(status, recv_utime); });
}

std::unique_ptr<ChildHandle> DeputyLink::MakeChild(const std::string& deputy, const std::string& name,
                                                   int stop_signal, double stop_timeout_s) {
  std::unique_ptr<Slot>& slot = slots_[name];
  if (!slot) {
    slot = std::make_unique<Slot>();
    slot->deputy = deputy;
    slot->name = name;
  }
  slot->stop_timeout_s = stop_timeout_s;
  slot->spec_stop_signal = stop_signal;
  return std::make_unique<RemoteChild>(this, slot.get());
}

bool DeputyLink::Heard(const std::string& deputy) const { return last_heard_.count(deputy) > 0; }

bool DeputyLink::Reachable(const std::string& deputy) const {
  const auto heard = last_heard_.find(deputy);
  return heard != last_heard_.end() && SecondsBetween(heard->second, Clock::now()) <= kDeputySilentAfterS;
}

void DeputyLink::OnStatus(const orbed::deputy_status_t& status, int64_t) {
  const std::string problem = CheckDeputyStatus(status);
  if (!problem.empty()) {
    process_->Reject(std::string(channels::kDeputyStatus) + "/invalid", problem);
    return;
  }
  bool ours = false;
  for (const auto& [name, slot] : slots_) ours = ours || slot->deputy == status.deputy;
  if (!ours) return;  // another launch's deputy
  const auto now = Clock::now();
  if (silent_[status.deputy]) {
    ORBED_LOG(kInfo) << "deputy " << status.deputy << " heard again after "
                     << SecondsBetween(last_heard_[status.deputy], now) << " s";
    silent_[status.deputy] = false;
  } else if (!Heard(status.deputy)) {
    ORBED_LOG(kInfo) << "deputy " << status.deputy << " is there";
  }
  last_heard_[status.deputy] = now;
  // A status for another launcher (an earlier one, or before it heard us) says nothing of ours;
  // after it followed us, it means the deputy let us go.
  if (status.launcher != launcher_id_) {
    if (followed_[status.deputy] && lost_.empty()) {
      lost_ = status.deputy;
      ORBED_LOG(kError) << "deputy " << status.deputy << " no longer follows this launch (it now follows '"
                        << EscapeText(status.launcher) << "')";
    }
    return;
  }
  followed_[status.deputy] = true;
  for (const orbed::deputy_child_t& child : status.children) {
    const auto it = slots_.find(child.name);
    if (it == slots_.end() || it->second->deputy != status.deputy) continue;
    Slot& slot = *it->second;
    if (child.instance > slot.instance) continue;  // cannot be: we never asked for it
    slot.reported_instance = child.instance;
    slot.pid = child.pid;
    slot.state = child.state;
    slot.exit_code = child.exit_code;
    slot.term_signal = child.term_signal;
    slot.detail = child.detail;
    slot.last_lines = child.last_lines;
  }
}

void DeputyLink::Send(const std::string& deputy) {
  orbed::deputy_command_t command{};
  command.utime = NowMicros();
  command.launcher = launcher_id_;
  command.launcher_start_utime = start_utime_;
  command.deputy = deputy;
  for (const auto& [name, slot] : slots_) {
    if (slot->deputy != deputy || slot->instance == 0) continue;
    orbed::deputy_process_t p{};
    p.name = slot->name;
    p.instance = slot->instance;
    p.run = slot->run;
    p.argv = slot->argv;
    p.argc = static_cast<int32_t>(p.argv.size());
    for (const auto& [key, value] : slot->env) {
      p.env_key.push_back(key);
      p.env_value.push_back(value);
    }
    p.num_env = static_cast<int32_t>(p.env_key.size());
    p.stop_signal = slot->stop_signal;
    p.stop_timeout_s = slot->stop_timeout_s;
    command.processes.push_back(std::move(p));
  }
  command.num_processes = static_cast<int32_t>(command.processes.size());
  command.run_dir = run_dir_;
  process_->PublishControl(channels::kDeputyCommand, command);
  last_sent_[deputy] = Clock::now();
  due_[deputy] = false;
}

std::string DeputyLink::LostDeputy() const { return lost_; }

void DeputyLink::SayGoodbye() {
  std::map<std::string, bool> deputies;
  for (const auto& [name, slot] : slots_) {
    if (slot->instance > 0) deputies[slot->deputy] = true;
  }
  for (const auto& [deputy, unused] : deputies) {
    orbed::deputy_command_t command{};
    command.utime = NowMicros();
    command.launcher = launcher_id_;
    command.launcher_start_utime = start_utime_;
    command.deputy = deputy;
    for (int copy = 0; copy < 3; ++copy) process_->PublishControl(channels::kDeputyCommand, command);
  }
}

void DeputyLink::Tick() {
  const auto now = Clock::now();
  std::map<std::string, bool> deputies;
  for (const auto& [name, slot] : slots_) {
    if (slot->instance > 0) deputies[slot->deputy] = true;
  }
  for (const auto& [deputy, unused] : deputies) {
    const auto sent = last_sent_.find(deputy);
    if (due_[deputy] || sent == last_sent_.end() || SecondsBetween(sent->second, now) >= kDeputyPeriodS) {
      Send(deputy);
    }
    const auto heard = last_heard_.find(deputy);
    if (heard != last_heard_.end() && !silent_[deputy] &&
        SecondsBetween(heard->second, now) > kDeputySilentAfterS) {
      silent_[deputy] = true;
      ORBED_LOG(kWarn) << "deputy " << deputy << " silent for " << SecondsBetween(heard->second, now)
                       << " s (its processes keep their last known state)";
    }
  }
}

}  // namespace orbed::launcher
