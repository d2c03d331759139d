// base/proc_stats.h against this test process itself, a child it starts, and /proc/net/udp text
// in the kernel's own layout.
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <ctime>
#include <string>

#include <gtest/gtest.h>

#include "base/proc_stats.h"

namespace orbed {
namespace {

TEST(ProcStats, ResidentMemoryOfALiveProcessAndOfNone) {
  const int64_t rss = ProcStatusKb(getpid(), "VmRSS");
  const int64_t peak = ProcStatusKb(getpid(), "VmHWM");
  EXPECT_GT(rss, 0);
  EXPECT_GE(peak, rss);
  EXPECT_EQ(ProcStatusKb(getpid(), "NoSuchField"), -1);
  EXPECT_EQ(ProcStatusKb(0x3fffffff, "VmRSS"), -1);
}

TEST(ProcStats, ChildrenAreFoundByTheirNameArgument) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // A shell that stays (the `; :` keeps it from exec'ing sleep) with "--name napper" in its argv,
    // in a group of its own so that its sleep goes with it.
    setpgid(0, 0);
    execl("/bin/sh", "sh", "-c", "sleep 30; :", "sh", "--name", "napper", static_cast<char*>(nullptr));
    _exit(127);
  }
  // exec replaces the command line a moment after fork: wait until /proc shows it.
  std::map<std::string, pid_t> children;
  for (int i = 0; i < 500 && children.empty(); ++i) {
    children = ChildrenByName(getpid());
    if (children.empty()) usleep(10000);
  }
  kill(-child, SIGKILL);
  kill(child, SIGKILL);  // in case it had not reached setpgid yet
  waitpid(child, nullptr, 0);
  ASSERT_EQ(children.size(), 1u);
  EXPECT_EQ(children.at("napper"), child);
  EXPECT_TRUE(ChildrenByName(0x3fffffff).empty());
}

TEST(ProcStats, ParsesTheDropsColumnByInode) {
  // Two rows as Linux 6 prints them, the header, and lines that are not rows.
  const std::string text =
      "   sl  local_address rem_address   st tx_queue rx_queue tr tm->when retrnsmt   uid  timeout inode ref "
      "pointer drops            \n"
      "11243: 0100007F:DBA5 00000000:0000 07 00000000:00000000 00:00000000 00000000     0        0 148171 2 "
      "000000002f25709f 17        \n"
      "  251: 43FFFFEF:1DF3 00000000:0000 07 00000000:00012000 00:00000000 00000000  1000        0 81235 2 "
      "0000000000000000 0         \n"
      "garbage line\n"
      " 9: short row\n";
  const auto drops = ParseUdpDropsByInode(text);
  ASSERT_EQ(drops.size(), 2u);
  EXPECT_EQ(drops.at(148171), 17);
  EXPECT_EQ(drops.at(81235), 0);
  EXPECT_TRUE(ParseUdpDropsByInode("").empty());
}

TEST(ProcStats, CpuTicksAreCountedFromTheLastParenthesis) {
  // Fields 3..15 after a name with a space and a ')': utime 250 and stime 40 ticks.
  EXPECT_EQ(ParseStatCpuTicks("1234 (we ird) x) S 1 2 3 4 5 6 7 8 9 10 250 40 0 0 20 0 1 0 100\n"), 290);
  EXPECT_EQ(ParseStatCpuTicks("1234 (short) S 1 2 3"), -1);
  EXPECT_EQ(ParseStatCpuTicks("1234 (bad) S 1 2 3 4 5 6 7 8 9 10 2x5 40"), -1);
  EXPECT_EQ(ParseStatCpuTicks("no parenthesis"), -1);
  EXPECT_EQ(ProcCpuSeconds(0x3fffffff), -1);
}

TEST(ProcStats, OwnCpuTimeAgreesWithTheProcessClock) {
  // The kernel's process CPU clock (clock_gettime) read before and after /proc: the ticks lie
  // between, up to two ticks of truncation.
  const auto cpu_s = [] {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  };
  volatile double sink = 0;
  while (cpu_s() < 0.1) sink = sink + 1;  // some CPU time of our own
  const double tick_s = 1.0 / static_cast<double>(sysconf(_SC_CLK_TCK));
  const double before = cpu_s();
  const double proc = ProcCpuSeconds(getpid());
  const double after = cpu_s();
  EXPECT_GE(proc, before - 2 * tick_s);
  EXPECT_LE(proc, after + tick_s);
}

TEST(ProcStats, OwnUdpSocketIsSeenWithNoDrops) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  EXPECT_FALSE(SocketInodes(getpid()).empty());
  EXPECT_EQ(UdpReceiveDrops(getpid()), 0);  // an unbound socket is listed with 0 drops, or not at all
  close(fd);
  EXPECT_EQ(UdpReceiveDrops(0x3fffffff), -1);
}

}  // namespace
}  // namespace orbed
