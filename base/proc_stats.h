#pragma once
/// @file
/// What Linux says about a live process, from /proc: its resident memory, its children by their
/// --name argument, and the datagrams the kernel dropped on its UDP sockets (its receive buffer was
/// full). The truth the bus cannot forge: tests and orbed-load read it beside what processes report
/// on PROCESS_STATUS.
///
/// Units: memory in kB (as /proc reports it, 1024 bytes), drops in datagrams (one per UDP fragment
/// of an LCM message: a large image is many datagrams).
/// Namespaces: /proc/net/udp lists the sockets of the reader's network namespace, so UdpReceiveDrops
/// sees another process's sockets only from inside that process's namespace.
/// Threading: the functions are pure readers of /proc and safe from any thread.

#include <sys/types.h>

#include <cstdint>
#include <map>
#include <set>
#include <string>

namespace orbed {

/// A "<field>:" line of /proc/<pid>/status in kB (e.g. field "VmRSS" resident now, "VmHWM" peak
/// resident), or -1 when the process is gone or has no such line.
int64_t ProcStatusKb(pid_t pid, const std::string& field);

/// The CPU time `pid` has used since it started, user + system over all its threads [s], or -1
/// when the process is gone.
double ProcCpuSeconds(pid_t pid);
/// User + system clock ticks (fields 14 and 15) from the text of /proc/<pid>/stat, or -1 when it
/// is malformed. The command name (field 2) may hold spaces and parentheses: the fields are counted
/// from its last ')'.
int64_t ParseStatCpuTicks(const std::string& stat);

/// The live children of `parent` whose command line has "--name NAME", by NAME (from
/// /proc/<parent>/task/*/children and each child's cmdline). orbed-launch passes every child its
/// --name, so this maps a launch file's process names to their pids.
std::map<std::string, pid_t> ChildrenByName(pid_t parent);

/// Parses the text of /proc/net/udp or /proc/net/udp6: socket inode → datagrams dropped on it.
/// Lines that are not socket rows (the header, malformed lines) are skipped.
std::map<uint64_t, int64_t> ParseUdpDropsByInode(const std::string& proc_net_udp);

/// The inodes of the sockets `pid` holds open (its /proc/<pid>/fd links "socket:[N]"); empty when
/// the process is gone or not ours to inspect.
std::set<uint64_t> SocketInodes(pid_t pid);

/// Datagrams the kernel dropped on `pid`'s UDP sockets since they were opened (the sum of the
/// drops column of /proc/net/udp and /proc/net/udp6 over its sockets), or -1 when the process is
/// gone. Reads the caller's network namespace (see the file comment).
int64_t UdpReceiveDrops(pid_t pid);

}  // namespace orbed
