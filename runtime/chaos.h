#pragma once
/// @file
/// Fault injection on the receive side: what the Process scaffold (runtime/process.h) does to
/// the datagrams of the channels it is told to hurt, before decoding, so that retries, idempotent
/// answers and duplicate handling are exercised over a real bus. Multicast hands every datagram to
/// every subscriber directly, so losses are made where a datagram is received, not in a proxy.
///
/// The spec (the common flag --chaos, default $ORBED_CHAOS): comma-separated key=value pairs,
///   drop=P        the datagram is not delivered, with probability P in [0, 1];
///   dup=P         it is delivered twice, the copy right after the original;
///   delay_ms=D    every datagram that is not dropped is held for a uniform time in [0, D] ms
///                 (D in [0, 10000]), so datagrams less than D apart may overtake each other;
///   reorder=P     it is held until the next datagram on its channel arrives and delivered right
///                 after that one (the two swap places), or after kReorderMaxHold_s if none comes;
///   seed=N        the seed of the draws (default 1);
///   channels=RE   only channels whose whole name matches the ECMAScript regular expression RE
///                 (default: every channel). Must come last: its value is the rest of the spec,
///                 commas included.
/// e.g. "drop=0.1,dup=0.05,delay_ms=30,reorder=0.05,seed=7,channels=SESSION_CONTROL|REGISTRATION".
/// An empty spec, or one whose probabilities and delay are all 0, injects nothing.
///
/// Draws: the fate of the k-th datagram (k = 0, 1, ..., counted per channel by this receiver) on
/// channel C received by the process named N is a pure function of (seed, N, C, k): each
/// probability is compared with its own uniform number, SplitMix64 over the seed, FNV-1a(N),
/// FNV-1a(C), k and the purpose (base/hash.h). The same process therefore loses the same datagrams
/// of the same traffic, and processes sharing one spec lose different ones.
///
/// Time: t_s is monotonic [s], passed in by the caller; nothing here reads a clock.
/// Memory: the queue holds the delayed datagrams (at most delay_ms worth of the hurt channels'
/// traffic) and one held datagram per channel; at most kMaxChannels channels are tracked, and a
/// channel first seen beyond that passes unharmed.
/// Threading: not synchronised; one thread (the Process::Run() thread).

#include <cstdint>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <utility>
#include <vector>

namespace orbed {

struct ChaosSpec {
  double drop{0};      ///< probability [0, 1]
  double dup{0};       ///< probability [0, 1]
  double reorder{0};   ///< probability [0, 1]
  double delay_ms{0};  ///< largest added delay [ms]
  std::uint64_t seed{1};
  std::string channels{".*"};  ///< ECMAScript regex, matched against the whole channel name

  /// True when anything can happen to a datagram.
  bool active() const { return drop > 0 || dup > 0 || reorder > 0 || delay_ms > 0; }
};

/// Parses a spec (see the file comment); "" gives the inactive default. Throws
/// std::invalid_argument naming the key and what it expects.
ChaosSpec ParseChaosSpec(const std::string& text);
/// The spec in its own syntax, every key given ("drop=0.1,dup=0,...,channels=.*").
std::string FormatChaosSpec(const ChaosSpec& spec);

/// What happens to one datagram.
struct ChaosFate {
  bool drop{false};
  bool duplicate{false};
  bool reorder{false};
  double delay_s{0};  ///< added delay [s], in [0, delay_ms / 1000]
};

/// The fate of the k-th datagram of channel `channel_hash` at receiver `receiver_hash`
/// (FNV-1a of the names) under `spec`. Pure.
ChaosFate DrawChaosFate(const ChaosSpec& spec, std::uint64_t receiver_hash, std::uint64_t channel_hash,
                        std::uint64_t k);

/// What a receiver did to the datagrams of the hurt channels.
struct ChaosCounts {
  std::int64_t datagrams{0};  ///< received on a hurt channel
  std::int64_t dropped{0};
  std::int64_t duplicated{0};
  std::int64_t delayed{0};    ///< held for a delay > 0
  std::int64_t reordered{0};  ///< held for the next datagram
};
/// "120 datagrams: 12 dropped, 6 duplicated, 118 delayed, 5 reordered".
std::string FormatChaosCounts(const ChaosCounts& counts);

/// The receive-side queue of one process: datagrams in as they arrive, out when due, in delivery
/// order.
class ChaosQueue {
 public:
  /// A received datagram; `target` is the caller's (the subscription it is for).
  struct Datagram {
    int target{0};
    std::string channel;
    std::vector<std::uint8_t> data;
    std::int64_t recv_utime{0};  ///< as received [µs since the epoch]; kept through delays
  };
  /// Longest a reordered datagram waits for the next one on its channel [s].
  static constexpr double kReorderMaxHold_s = 0.5;
  static constexpr std::size_t kMaxChannels = 1024;

  /// Throws std::invalid_argument for a malformed channels regex.
  ChaosQueue(const ChaosSpec& spec, const std::string& receiver_name);

  /// True when datagrams of `channel` are hurt (it matches and is tracked); others are the
  /// caller's to deliver at once.
  bool Applies(const std::string& channel);
  /// A datagram of a channel that Applies() arrived at t_s: draws its fate and queues what is to
  /// be delivered (possibly nothing, possibly due at once).
  void Receive(Datagram datagram, double t_s);
  /// Removes and returns every datagram due at or before t_s, in delivery order (due time, then
  /// arrival order; a duplicate and a released datagram right after the one they follow).
  std::vector<Datagram> TakeDue(double t_s);
  /// The earliest time anything queued or held is due [s]; +infinity when nothing is.
  double NextDue() const;

  const ChaosSpec& spec() const { return spec_; }
  const ChaosCounts& counts() const { return counts_; }

 private:
  struct Held {
    Datagram datagram;
    bool duplicate{false};
    double deadline_s{0};
  };
  struct Channel {
    bool applies{false};
    std::uint64_t hash{0};
    std::uint64_t count{0};  // datagrams received so far: the next one's k
    std::optional<Held> held;
  };

  // Queues `datagram` (and its copy when `duplicate`) for due_s, after everything queued for the
  // same time.
  void Schedule(Datagram datagram, bool duplicate, double due_s);
  // Queues the channel's held datagram (if any) for due_s.
  void Release(Channel* channel, double due_s);

  ChaosSpec spec_;
  std::regex regex_;
  std::uint64_t receiver_hash_;
  std::map<std::string, Channel> channels_;
  std::map<std::pair<double, std::uint64_t>, Datagram> queue_;  // (due [s], sequence) → datagram
  std::uint64_t sequence_{0};
  ChaosCounts counts_;
};

}  // namespace orbed
