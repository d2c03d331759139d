// Launch across hosts (launcher and deputies): three network namespaces as hosts A, B and C, each joined by a
// veth pair to one bridge in this test's own private namespace (addresses 10.77.0.0/24, which
// exist only in here), LCM's multicast with ttl=1 between them and nothing else reachable. On A
// orbed-launch runs scripts/launch/viraal.yaml with the registration server placed on B and the
// headset on C (`placement:`), through `orbed-launch --deputy` on B and C. The ViRAAl run
// completes with the pinned results; every process's heartbeat names its host; C's link, cut for
// 5 s in the middle of the run, shows as SILENT in the monitor and in the launcher, and the run
// resumes when it returns. Hosts may have disks of their own: each a tmpfs in a private mount
// namespace, empty at the start, where every process keeps its state (its deputy's run folder).
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/process_status_t.hpp>

#include "tests/integration/logged.h"
#include "tests/integration/testbed_util.h"
#include "tests/same_tree.h"

namespace orbed::testing {
namespace {

// LCM between the hosts: the bus's group and port, packets allowed one hop (the bridge).
constexpr char kLanUrl[] = "udpm://239.255.76.67:7667?ttl=1";

bool Shell(const std::string& command) {
  const int status = std::system(command.c_str());
  EXPECT_EQ(status, 0) << command;
  return status == 0;
}

// Hosts as network namespaces on one bridge. Each host is a namespace held open by a sleeping
// process; commands run in it through nsenter. Everything lives inside the test's own namespace
// and goes with it. With a `disk` (a folder), each host also has a mount namespace of its own with
// an empty tmpfs mounted there: the same path, a different disk on every host (gone with it).
class VirtualLan {
 public:
  // Hosts named `hosts`, as 10.77.0.1, .2, ...
  explicit VirtualLan(const std::vector<std::string>& hosts, std::string disk = "") : disk_(std::move(disk)) {
    ok_ = Shell("ip link add orbedbr0 type bridge mcast_snooping 0 && ip link set orbedbr0 up");
    // The test itself listens on the bridge (an observer, not a host).
    ok_ =
        ok_ && Shell("ip addr add 10.77.0.254/24 dev orbedbr0 && ip route replace 224.0.0.0/4 dev orbedbr0");
    for (size_t i = 0; i < hosts.size() && ok_; ++i) AddHost(hosts[i], static_cast<int>(i) + 1);
  }
  ~VirtualLan() {
    // The veth pairs are deleted here, both ends at once: left to go with their hosts' namespaces
    // (the holders, stopped after this), they may outlive this LAN (the kernel tears a namespace
    // down later) and collide with the next LAN's links of the same names.
    for (const auto& [name, host] : hosts_)
      std::system(("ip link del " + host.link + " 2>/dev/null").c_str());
    std::system("ip link del orbedbr0 2>/dev/null; ip route replace 224.0.0.0/4 dev lo");
  }
  bool ok() const { return ok_; }

  // Adds host `name` as 10.77.0.<index>.
  void AddHost(const std::string& name, int index) {
    auto holder = std::make_unique<RunningProcess>(
        disk_.empty()
            ? std::vector<std::string>{"/usr/bin/unshare", "-n", "sleep", "3600"}
            : std::vector<std::string>{"/usr/bin/unshare", "-n", "-m", "--propagation", "private", "/bin/sh",
                                       "-c", "mount -t tmpfs orbed-disk '" + disk_ + "' && exec sleep 3600"});
    const std::string pid = std::to_string(holder->pid());
    // The holder is in its namespace once its /proc entry points at another one than ours (and
    // has its disk once its mounts list it).
    if (!WaitFor(
            [&] {
              return NetNamespace("/proc/" + pid) != NetNamespace("/proc/self") &&
                     (disk_.empty() || HasMount("/proc/" + pid, disk_));
            },
            10)) {
      ADD_FAILURE() << "host " << name << ": no network namespace (or disk) of its own";
      ok_ = false;
      return;
    }
    const std::string outside = "ve" + std::to_string(index), inside = "eth" + std::to_string(index);
    const std::string in_host = "nsenter --target " + pid + " --net ";
    ok_ = ok_ && Shell("ip link add " + outside + " type veth peer name " + inside + " && ip link set " +
                       inside + " netns " + pid + " && ip link set " + outside + " master orbedbr0 up");
    ok_ = ok_ && Shell(in_host + "ip link set lo up && " + in_host + "ip addr add 10.77.0." +
                       std::to_string(index) + "/24 dev " + inside + " && " + in_host + "ip link set " +
                       inside + " up && " + in_host + "ip route add 224.0.0.0/4 dev " + inside);
    hosts_[name] = Host{pid, outside, std::move(holder)};
  }

  // argv run on `host`, with the LAN's LCM URL.
  std::unique_ptr<RunningProcess> Run(const std::string& host, std::vector<std::string> argv,
                                      std::map<std::string, std::string> env = {}) {
    argv.insert(argv.begin(), {"/usr/bin/nsenter", "--target", hosts_.at(host).pid, "--net", "--"});
    if (!disk_.empty()) argv.insert(argv.begin() + 4, "--mount");
    env["ORBED_LCM_URL"] = kLanUrl;
    return std::make_unique<RunningProcess>(argv, env);
  }

  // `path` as seen from this test, on `host`'s disk.
  std::string OnHost(const std::string& host, const std::string& path) const {
    return "/proc/" + hosts_.at(host).pid + "/root" + path;
  }

  // Takes `host`'s link down or up (at the bridge).
  void SetLink(const std::string& host, bool up) {
    Shell("ip link set " + hosts_.at(host).link + (up ? " up" : " down"));
  }

 private:
  static std::string NetNamespace(const std::string& proc) {
    std::error_code ec;
    return std::filesystem::read_symlink(proc + "/ns/net", ec).string();
  }
  // Whether `proc`'s mount namespace has a tmpfs mounted on `path`.
  static bool HasMount(const std::string& proc, const std::string& path) {
    std::ifstream mounts(proc + "/mountinfo");
    for (std::string line; std::getline(mounts, line);) {
      if (line.find(" " + path + " ") != std::string::npos && line.find(" tmpfs ") != std::string::npos) {
        return true;
      }
    }
    return false;
  }
  struct Host {
    std::string pid, link;
    std::unique_ptr<RunningProcess> holder;
  };
  std::string disk_;
  bool ok_ = false;
  std::map<std::string, Host> hosts_;
};

// Hosts are network namespaces made by root inside the test's own (scripts/netns-exec).
bool CanBuildHosts() { return std::getenv("ORBED_IN_NETNS") != nullptr && geteuid() == 0; }
constexpr char kNoHosts[] = "needs root in a private network namespace (scripts/netns-exec as root)";

bool AnyLineHas(const std::vector<std::string>& lines, const std::string& a, const std::string& b = "") {
  for (const std::string& line : lines) {
    if (line.find(a) != std::string::npos && line.find(b) != std::string::npos) return true;
  }
  return false;
}

TEST(Hosts, TheViraalRunOnThreeHostsCompletesAndSurvivesAPartition) {
  if (!CanBuildHosts()) GTEST_SKIP() << kNoHosts;
  VirtualLan lan({"hostA", "hostB", "hostC"});
  ASSERT_TRUE(lan.ok());

  const std::string dir = MakeTempDir("hosts");
  std::ofstream(dir + "/three_hosts.yaml")
      << "name: three_hosts\n"
      << "include: [" << SourcePath("scripts/launch/viraal.yaml") << "]\n"
      << "placement: {registration: hostB, hmd: hostC}\n";
  // One disk shared by all: the deputies' run folder is the launcher's.
  const auto deputy_b = lan.Run("hostB", {BinPath("orbed-launch"), "--deputy", "hostB", "--log-root", dir});
  const auto deputy_c = lan.Run("hostC", {BinPath("orbed-launch"), "--deputy", "hostC", "--log-root", dir});

  lcm::LCM observer(kLanUrl);
  ASSERT_TRUE(observer.good());
  int trials = 0;
  observer.subscribeFunction(
      "ALIGNMENT_TRIAL", +[](const lcm::ReceiveBuffer*, const std::string&, int* n) { ++*n; }, &trials);

  const std::string log_dir = dir + "/log";
  const auto launcher = lan.Run("hostA",
                                {BinPath("orbed-launch"), dir + "/three_hosts.yaml", "--host", "hostA",
                                 "--arg", "run_id=pinned", "--duration-s", "240"},
                                {{"ORBED_LOG_DIR", log_dir}});
  // The partition starts with the first trial heard from C.
  ASSERT_TRUE(WaitFor(
      [&] {
        observer.handleTimeout(10);
        return trials > 0 || !launcher->running();
      },
      120));
  ASSERT_TRUE(launcher->running()) << "the run ended before its first trial";
  lan.SetLink("hostC", false);
  // Cut for 5 s of wall time (the partition's length, not a wait for anything).
  std::this_thread::sleep_for(std::chrono::seconds(5));
  lan.SetLink("hostC", true);
  ASSERT_TRUE(launcher->Wait(180)) << "the run did not finish after the partition";
  EXPECT_EQ(launcher->exit_code(), 0);

  // The run: the pinned numbers of the single-host run.
  ExpectSameTree(YAML::LoadFile(SourcePath("tests/integration/testdata/viraal_pinned_results.json")),
                 YAML::LoadFile(log_dir + "/results.json"), "results", {"started_utime", "duration_s"});
  EXPECT_TRUE(YAML::LoadFile(log_dir + "/manifest.json")["complete"].as<bool>());

  // Every process says where it ran.
  std::map<std::string, std::string> host_of;
  for (const orbed::process_status_t& status : Logged<orbed::process_status_t>(log_dir, "PROCESS_STATUS")) {
    host_of[status.name] = status.host;
  }
  EXPECT_EQ(host_of["sim"], "hostA");
  EXPECT_EQ(host_of["logger"], "hostA");
  EXPECT_EQ(host_of["scenario"], "hostA");
  EXPECT_EQ(host_of["registration"], "hostB");
  EXPECT_EQ(host_of["hmd"], "hostC");
  EXPECT_EQ(host_of["deputy-hostC"], "hostC");

  // The partition, as the monitor (on A) and the launcher saw it.
  const std::vector<std::string>& said = launcher->lines();
  EXPECT_TRUE(AnyLineHas(said, "hmd on hostC: SILENT")) << "the monitor did not flag the headset";
  EXPECT_TRUE(AnyLineHas(said, "hmd on hostC: heard again after"));
  EXPECT_TRUE(AnyLineHas(said, "deputy hostC silent for"));
  EXPECT_TRUE(AnyLineHas(said, "deputy hostC heard again after"));
  // B was never cut off.
  EXPECT_FALSE(AnyLineHas(said, "registration on hostB: SILENT"));
}

// A process on another host that dies is respawned there, through its deputy, as a local one
// would be: the headset on B, SIGKILLed after the first trial, comes back as a new instance (a new
// pid, ready again at its heartbeat) and the run completes.
// What a test of a killed headset hears on the LAN: the alignment trials answered, and every pid
// that sent a PROCESS_STATUS as "hmd" (a respawned headset is a second one).
struct HeadsetWatch {
  int trials = 0;
  std::set<int> hmd_pids;

  void Subscribe(lcm::LCM* observer) {
    observer->subscribeFunction(
        "ALIGNMENT_TRIAL",
        +[](const lcm::ReceiveBuffer*, const std::string&, HeadsetWatch* s) { ++s->trials; }, this);
    observer->subscribeFunction(
        "PROCESS_STATUS",
        +[](const lcm::ReceiveBuffer* rbuf, const std::string&, HeadsetWatch* s) {
          orbed::process_status_t status;
          if (status.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) > 0 && status.name == "hmd") {
            s->hmd_pids.insert(status.pid);
          }
        },
        this);
  }
};

TEST(Hosts, AProcessKilledOnAnotherHostIsRespawnedThroughItsDeputy) {
  if (!CanBuildHosts()) GTEST_SKIP() << kNoHosts;
  VirtualLan lan({"hostA", "hostB"});
  ASSERT_TRUE(lan.ok());
  const std::string dir = MakeTempDir("hosts_respawn");
  std::ofstream(dir + "/two_hosts.yaml") << "name: two_hosts\n"
                                         << "include: [" << SourcePath("scripts/launch/viraal.yaml") << "]\n"
                                         << "placement: {hmd: hostB}\n";
  const auto deputy_b = lan.Run("hostB", {BinPath("orbed-launch"), "--deputy", "hostB", "--log-root", dir});

  HeadsetWatch seen;
  lcm::LCM observer(kLanUrl);
  ASSERT_TRUE(observer.good());
  seen.Subscribe(&observer);
  const std::string log_dir = dir + "/log";
  const auto launcher = lan.Run("hostA",
                                {BinPath("orbed-launch"), dir + "/two_hosts.yaml", "--host", "hostA", "--arg",
                                 "run_id=respawn", "--duration-s", "240"},
                                {{"ORBED_LOG_DIR", log_dir}});
  ASSERT_TRUE(WaitFor(
      [&] {
        observer.handleTimeout(10);
        return (seen.trials > 0 && !seen.hmd_pids.empty()) || !launcher->running();
      },
      120));
  ASSERT_TRUE(launcher->running()) << "the run ended before its first trial";
  ASSERT_EQ(seen.hmd_pids.size(), 1u);
  ASSERT_EQ(kill(*seen.hmd_pids.begin(), SIGKILL), 0);
  ASSERT_TRUE(WaitFor(
      [&] {
        observer.handleTimeout(10);
        return !launcher->running();
      },
      180))
      << "the run did not finish after the headset was killed";
  EXPECT_EQ(launcher->exit_code(), 0);
  EXPECT_EQ(seen.hmd_pids.size(), 2u) << "no second instance of the headset was heard";
  EXPECT_TRUE(AnyLineHas(launcher->lines(), "hmd killed by signal", "on hostB; respawning"));
  EXPECT_TRUE(AnyLineHas(launcher->lines(), "hmd is ready again"));
  const YAML::Node results = YAML::LoadFile(log_dir + "/results.json");
  EXPECT_EQ(results["status"].as<std::string>(), "ok");
  ASSERT_EQ(results["sessions"].size(), 2u);
  for (const auto& session : results["sessions"]) EXPECT_EQ(session["trials"].size(), 3u);
}

// The live processes (not zombies) whose environment holds every one of `entries` ("KEY=value").
std::vector<int> PidsWithEnv(const std::vector<std::string>& entries) {
  std::vector<int> pids;
  for (const auto& dir : std::filesystem::directory_iterator("/proc")) {
    const std::string name = dir.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream environ(dir.path() / "environ", std::ios::binary);  // empty for a zombie
    std::set<std::string> variables;
    for (std::string variable; std::getline(environ, variable, '\0');) variables.insert(variable);
    if (std::all_of(entries.begin(), entries.end(), [&](const std::string& e) { return variables.count(e); }))
      pids.push_back(std::stoi(name));
  }
  return pids;
}

// orbed-launch on A SIGKILLed: nothing of its run is left on A at once (PR_SET_PDEATHSIG), nor on
// B once B's deputy has heard nothing for its orphan timeout (3 s here) and stopped what it
// started, SIGKILL included for a process that ignores its stop signal (after its
// stop_timeout_s, 1 s).
TEST(Hosts, ASigkilledLauncherLeavesNoProcessOnAnyHost) {
  if (!CanBuildHosts()) GTEST_SKIP() << kNoHosts;
  VirtualLan lan({"hostA", "hostB"});
  ASSERT_TRUE(lan.ok());
  const std::string dir = MakeTempDir("hosts_launcher_killed");
  const std::string mark = "ORBED_RUN_MARK=" + dir;
  const std::string env = "env: {ORBED_RUN_MARK: \"" + dir + "\"}";
  const std::string deaf =
      "command: sh, args: [-c, 'trap \"\" INT TERM; exec sleep 600'], ready: none, stop_timeout_s: 1";
  std::ofstream(dir + "/killed.yaml")
      << "name: killed\n"
      << "groups:\n"
      << "  - name: g\n"
      << "    processes:\n"
      << "      - {name: deaf_a, " << deaf << ", " << env << "}\n"
      << "      - {name: deaf_b, host: hostB, " << deaf << ", " << env << "}\n"
      << "      - {name: monitor_b, command: orbed-monitor, host: hostB, " << env << "}\n";
  constexpr double kOrphanTimeoutS = 3, kStopTimeoutS = 1;
  const auto deputy_b = lan.Run("hostB", {BinPath("orbed-launch"), "--deputy", "hostB", "--orphan-timeout-s",
                                          std::to_string(kOrphanTimeoutS)});
  const auto launcher = lan.Run("hostA", {BinPath("orbed-launch"), dir + "/killed.yaml", "--host", "hostA"});
  ASSERT_TRUE(WaitFor(
      [&] {
        launcher->running();  // prints its output
        return PidsWithEnv({mark}).size() == 3 && AnyLineHas(launcher->lines(), "monitor_b is ready");
      },
      60))
      << "the run did not start on both hosts";
  ASSERT_EQ(PidsWithEnv({mark, "ORBED_HOST=hostA"}).size(), 1u);
  ASSERT_EQ(PidsWithEnv({mark, "ORBED_HOST=hostB"}).size(), 2u);

  launcher->Signal(SIGKILL);
  ASSERT_TRUE(launcher->Wait(10));
  ASSERT_EQ(launcher->term_signal(), SIGKILL);
  // On A: at once (the deadline only bounds the kernel's delivery of the parent-death signal).
  EXPECT_TRUE(WaitFor(
      [&] {
        return PidsWithEnv({mark, "ORBED_HOST=hostA"}).empty();
      },
      5))
      << "a process on A outlived its launcher";
  // On B: within the orphan timeout and the stop's SIGKILL, plus slack for the deputy's 20 ms
  // ticks on a busy machine.
  EXPECT_TRUE(WaitFor([&] { return PidsWithEnv({mark}).empty(); }, kOrphanTimeoutS + kStopTimeoutS + 5))
      << "a process on B outlived its launcher's orphan timeout";
  EXPECT_TRUE(WaitFor(
      [&] {
        deputy_b->running();
        return AnyLineHas(deputy_b->lines(), "no command from", "stopping what it started") &&
               AnyLineHas(deputy_b->lines(), "deaf_b did not stop within 1 s: SIGKILL");
      },
      5));
}

// Hosts with disks of their own, each empty at the start: the headset on B and the registration
// server on C keep their state (hmd.state, registration.journal) in their own host's folder of the
// run, which their deputies make; the run survives a 30 s partition of C (the conductor's requests
// wait out their 60 s deadline, re-sent meanwhile) and a SIGKILL of the headset on B, which comes
// back in its session from B's own hmd.state.
TEST(Hosts, HostsWithTheirOwnDisksRideOutAPartitionAndAKilledHeadset) {
  if (!CanBuildHosts()) GTEST_SKIP() << kNoHosts;
  const std::string dir = MakeTempDir("hosts_disks");
  const std::string disk = dir + "/logs";  // every host's logs folder: its own tmpfs
  std::filesystem::create_directories(disk);
  VirtualLan lan({"hostA", "hostB", "hostC"}, disk);
  ASSERT_TRUE(lan.ok());
  std::ofstream(dir + "/own_disks.yaml") << "name: own_disks\n"
                                         << "include: [" << SourcePath("scripts/launch/viraal.yaml") << "]\n"
                                         << "placement: {hmd: hostB, registration: hostC}\n";
  const auto deputy_b = lan.Run("hostB", {BinPath("orbed-launch"), "--deputy", "hostB", "--log-root", disk});
  const auto deputy_c = lan.Run("hostC", {BinPath("orbed-launch"), "--deputy", "hostC", "--log-root", disk});

  HeadsetWatch seen;
  lcm::LCM observer(kLanUrl);
  ASSERT_TRUE(observer.good());
  seen.Subscribe(&observer);
  // A's run folder, on A's disk (as scripts/orbed makes it there).
  const std::string run = disk + "/own-disks-run";
  ASSERT_TRUE(std::filesystem::create_directory(lan.OnHost("hostA", run)));
  const auto launcher = lan.Run("hostA",
                                {BinPath("orbed-launch"), dir + "/own_disks.yaml", "--host", "hostA", "--arg",
                                 "run_id=own-disks", "--duration-s", "400"},
                                {{"ORBED_LOG_DIR", run}});
  // Everyone's output is read while waiting (a full pipe would stall the writer).
  auto watch = [&] {
    observer.handleTimeout(10);
    deputy_b->running();
    deputy_c->running();
    return launcher->running();
  };
  ASSERT_TRUE(WaitFor([&] { return !watch() || (seen.trials > 0 && !seen.hmd_pids.empty()); }, 120));
  ASSERT_TRUE(launcher->running()) << "the run ended before its first trial";

  // C cut off for 30 s of wall time (the partition's length, not a wait for anything).
  lan.SetLink("hostC", false);
  const auto cut_until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < cut_until) watch();
  lan.SetLink("hostC", true);
  ASSERT_TRUE(launcher->running()) << "the run ended during the partition";

  // The next trial after it, then the headset on B killed.
  const int trials_before = seen.trials;
  ASSERT_TRUE(WaitFor([&] { return !watch() || seen.trials > trials_before; }, 120));
  ASSERT_TRUE(launcher->running()) << "the run ended before the headset could be killed";
  ASSERT_EQ(seen.hmd_pids.size(), 1u);
  ASSERT_EQ(kill(*seen.hmd_pids.begin(), SIGKILL), 0);
  ASSERT_TRUE(WaitFor([&] { return !watch(); }, 300)) << "the run did not finish";
  EXPECT_EQ(launcher->exit_code(), 0);
  EXPECT_EQ(seen.hmd_pids.size(), 2u) << "no second instance of the headset was heard";

  const std::vector<std::string>& said = launcher->lines();
  EXPECT_TRUE(AnyLineHas(said, "deputy hostC silent for"));
  EXPECT_TRUE(AnyLineHas(said, "deputy hostC heard again after"));
  EXPECT_TRUE(AnyLineHas(said, "hmd killed by signal", "on hostB; respawning"));
  EXPECT_TRUE(AnyLineHas(said, "hmd is ready again"));
  EXPECT_FALSE(AnyLineHas(said, "registration exited")) << "the registration server failed on C";
  const YAML::Node results = YAML::LoadFile(lan.OnHost("hostA", run + "/results.json"));
  EXPECT_EQ(results["status"].as<std::string>(), "ok");
  ASSERT_EQ(results["sessions"].size(), 2u);
  for (const auto& session : results["sessions"]) EXPECT_EQ(session["trials"].size(), 3u);
  // Each kept its state on its own host's disk, in the run's folder there.
  EXPECT_TRUE(std::filesystem::exists(lan.OnHost("hostB", run + "/hmd.state")));
  EXPECT_TRUE(std::filesystem::exists(lan.OnHost("hostC", run + "/registration.journal")));
  EXPECT_TRUE(std::filesystem::exists(lan.OnHost("hostA", run + "/sim.state")));
  EXPECT_FALSE(std::filesystem::exists(lan.OnHost("hostA", run + "/hmd.state")));
  EXPECT_FALSE(std::filesystem::exists(lan.OnHost("hostA", run + "/registration.journal")));
}

// A process that fails on another host says why on the launcher's terminal: its last lines of
// output come back in its deputy's status and are printed with its exit.
TEST(Hosts, AProcessFailingOnAnotherHostSaysWhyOnTheLaunchersTerminal) {
  if (!CanBuildHosts()) GTEST_SKIP() << kNoHosts;
  VirtualLan lan({"hostA", "hostB"});
  ASSERT_TRUE(lan.ok());
  const std::string dir = MakeTempDir("hosts_why");
  std::ofstream(dir + "/why.yaml")
      << "name: why\n"
      << "groups:\n"
      << "  - name: far\n"
      << "    processes:\n"
      << "      - {name: registration, command: orbed-registration, host: hostB,\n"
      << "         args: [--journal, /nonexistent-folder/registration.journal]}\n";
  const auto deputy_b = lan.Run("hostB", {BinPath("orbed-launch"), "--deputy", "hostB"});
  const auto launcher = lan.Run("hostA", {BinPath("orbed-launch"), dir + "/why.yaml", "--host", "hostA"});
  ASSERT_TRUE(WaitFor(
      [&] {
        deputy_b->running();
        return !launcher->running();
      },
      60));
  EXPECT_EQ(launcher->exit_code(), 1);
  EXPECT_TRUE(AnyLineHas(launcher->lines(), "exited with code 1 on hostB"));
  EXPECT_TRUE(AnyLineHas(launcher->lines(), "registration | [hostB]", "cannot open the journal"));
}

// A process placed on a host whose deputy never answers: the launch stops with an error naming the
// host and what to start there.
TEST(Hosts, AHostWithoutADeputyIsNamedInTheError) {
  const std::string dir = MakeTempDir("no_deputy");
  std::ofstream(dir + "/lonely.yaml") << "name: lonely\n"
                                      << "groups:\n"
                                      << "  - name: far\n"
                                      << "    processes:\n"
                                      << "      - {name: monitor, command: orbed-monitor, host: nowhere,\n"
                                      << "         ready_timeout_s: 2}\n";
  RunningProcess launcher({BinPath("orbed-launch"), dir + "/lonely.yaml", "--host", "here"});
  ASSERT_TRUE(launcher.Wait(60));
  EXPECT_EQ(launcher.exit_code(), 1);
  EXPECT_TRUE(AnyLineHas(launcher.lines(), "placed on host 'nowhere'", "orbed-launch --deputy nowhere"));
}

}  // namespace
}  // namespace orbed::testing
