#include "base/proc_stats.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

namespace orbed {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string ProcPath(pid_t pid, const std::string& rest) {
  return "/proc/" + std::to_string(pid) + "/" + rest;
}

}  // namespace

int64_t ProcStatusKb(pid_t pid, const std::string& field) {
  std::ifstream status(ProcPath(pid, "status"));
  const std::string key = field + ":";
  std::string line;
  while (std::getline(status, line)) {
    if (line.compare(0, key.size(), key) != 0) continue;
    std::istringstream value(line.substr(key.size()));
    int64_t kb = -1;
    return value >> kb ? kb : -1;
  }
  return -1;
}

int64_t ParseStatCpuTicks(const std::string& stat) {
  const size_t name_end = stat.rfind(')');
  if (name_end == std::string::npos) return -1;
  // After the name: field 3 (state) onwards; utime and stime are fields 14 and 15.
  std::istringstream fields(stat.substr(name_end + 1));
  std::vector<std::string> f((std::istream_iterator<std::string>(fields)),
                             std::istream_iterator<std::string>());
  constexpr size_t kUtime = 14 - 3, kStime = 15 - 3;
  if (f.size() <= kStime) return -1;
  try {
    size_t used_u = 0, used_s = 0;
    const int64_t utime = std::stoll(f[kUtime], &used_u);
    const int64_t stime = std::stoll(f[kStime], &used_s);
    if (used_u != f[kUtime].size() || used_s != f[kStime].size() || utime < 0 || stime < 0) return -1;
    return utime + stime;
  } catch (const std::exception&) {
    return -1;
  }
}

double ProcCpuSeconds(pid_t pid) {
  const int64_t ticks = ParseStatCpuTicks(ReadAll(ProcPath(pid, "stat")));
  const long ticks_per_s = sysconf(_SC_CLK_TCK);
  if (ticks < 0 || ticks_per_s <= 0) return -1;
  return static_cast<double>(ticks) / static_cast<double>(ticks_per_s);
}

std::map<std::string, pid_t> ChildrenByName(pid_t parent) {
  std::map<std::string, pid_t> children;
  std::error_code ec;
  for (const auto& task : fs::directory_iterator(ProcPath(parent, "task"), ec)) {
    std::ifstream list(task.path() / "children");
    pid_t pid = 0;
    while (list >> pid) {
      std::ifstream cmdline(ProcPath(pid, "cmdline"));
      std::vector<std::string> args;
      std::string arg;
      while (std::getline(cmdline, arg, '\0')) args.push_back(arg);
      for (size_t i = 0; i + 1 < args.size(); ++i) {
        if (args[i] == "--name") children[args[i + 1]] = pid;
      }
    }
  }
  return children;
}

std::map<uint64_t, int64_t> ParseUdpDropsByInode(const std::string& proc_net_udp) {
  // Columns: sl local_address rem_address st tx_queue:rx_queue tr:tm->when retrnsmt uid timeout
  // inode ref pointer drops.
  constexpr size_t kInode = 9, kDrops = 12;
  std::map<uint64_t, int64_t> drops;
  std::istringstream lines(proc_net_udp);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::vector<std::string> f((std::istream_iterator<std::string>(fields)),
                               std::istream_iterator<std::string>());
    if (f.size() <= kDrops || f[0].empty() || f[0].back() != ':') continue;
    try {
      size_t used_inode = 0, used_drops = 0;
      const uint64_t inode = std::stoull(f[kInode], &used_inode);
      const int64_t dropped = std::stoll(f[kDrops], &used_drops);
      if (used_inode != f[kInode].size() || used_drops != f[kDrops].size()) continue;
      drops[inode] += dropped;
    } catch (const std::exception&) {
      continue;  // not a socket row
    }
  }
  return drops;
}

std::set<uint64_t> SocketInodes(pid_t pid) {
  std::set<uint64_t> inodes;
  std::error_code ec;
  for (const auto& fd : fs::directory_iterator(ProcPath(pid, "fd"), ec)) {
    std::error_code link_ec;
    const std::string target = fs::read_symlink(fd.path(), link_ec).string();
    constexpr char kPrefix[] = "socket:[";
    if (link_ec || target.compare(0, sizeof(kPrefix) - 1, kPrefix) != 0 || target.back() != ']') continue;
    try {
      inodes.insert(std::stoull(target.substr(sizeof(kPrefix) - 1)));
    } catch (const std::exception&) {
    }
  }
  return inodes;
}

int64_t UdpReceiveDrops(pid_t pid) {
  if (!fs::exists(ProcPath(pid, "status"))) return -1;
  const std::set<uint64_t> mine = SocketInodes(pid);
  int64_t total = 0;
  for (const char* table : {"/proc/net/udp", "/proc/net/udp6"}) {
    for (const auto& [inode, dropped] : ParseUdpDropsByInode(ReadAll(table))) {
      if (mine.count(inode) > 0) total += dropped;
    }
  }
  return total;
}

}  // namespace orbed
