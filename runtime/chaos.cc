#include "runtime/chaos.h"

#include <algorithm>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "base/hash.h"
#include "base/number_list.h"

namespace orbed {
namespace {

// DrawChaosFate() purposes: one independent uniform number each.
enum Purpose : std::uint64_t { kDrop = 1, kDuplicate = 2, kReorder = 3, kDelay = 4 };

double Uniform(std::uint64_t seed, std::uint64_t receiver_hash, std::uint64_t channel_hash, std::uint64_t k,
               Purpose purpose) {
  return UnitInterval(
      SplitMix64(SplitMix64(SplitMix64(SplitMix64(seed ^ receiver_hash) ^ channel_hash) ^ k) ^ purpose));
}

double Number(const std::string& key, const std::string& value, double max) {
  const std::vector<double> numbers = ParseNumberList(value, "chaos spec " + key);
  if (numbers.size() != 1 || numbers[0] < 0 || numbers[0] > max) {
    std::ostringstream out;
    out << "chaos spec " << key << ": expected one number in [0, " << max << "], got '" << value << "'";
    throw std::invalid_argument(out.str());
  }
  return numbers[0];
}

std::uint64_t Seed(const std::string& value) {
  size_t used = 0;
  std::uint64_t seed = 0;
  try {
    if (value.empty() || value[0] < '0' || value[0] > '9') throw std::invalid_argument(value);
    seed = std::stoull(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size()) {
    throw std::invalid_argument("chaos spec seed: expected an unsigned integer, got '" + value + "'");
  }
  return seed;
}

}  // namespace

ChaosSpec ParseChaosSpec(const std::string& text) {
  ChaosSpec spec;
  size_t start = 0;
  while (start < text.size()) {
    const size_t equals = text.find('=', start);
    const size_t comma = text.find(',', start);
    if (equals == std::string::npos || (comma != std::string::npos && comma < equals)) {
      throw std::invalid_argument("chaos spec: expected key=value, got '" +
                                  text.substr(start, comma - start) +
                                  "' (keys: drop, dup, delay_ms, reorder, seed, channels)");
    }
    const std::string key = text.substr(start, equals - start);
    if (key == "channels") {  // the rest of the spec, commas included
      spec.channels = text.substr(equals + 1);
      if (spec.channels.empty()) throw std::invalid_argument("chaos spec channels: empty regular expression");
      try {
        std::regex check(spec.channels);
      } catch (const std::regex_error& e) {
        throw std::invalid_argument("chaos spec channels: invalid regular expression '" + spec.channels +
                                    "': " + e.what());
      }
      break;
    }
    const size_t end = comma == std::string::npos ? text.size() : comma;
    const std::string value = text.substr(equals + 1, end - equals - 1);
    if (key == "drop") {
      spec.drop = Number(key, value, 1);
    } else if (key == "dup") {
      spec.dup = Number(key, value, 1);
    } else if (key == "reorder") {
      spec.reorder = Number(key, value, 1);
    } else if (key == "delay_ms") {
      spec.delay_ms = Number(key, value, 10000);
    } else if (key == "seed") {
      spec.seed = Seed(value);
    } else {
      throw std::invalid_argument("chaos spec: unknown key '" + key +
                                  "' (keys: drop, dup, delay_ms, reorder, seed, channels)");
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
    if (start == text.size()) throw std::invalid_argument("chaos spec: trailing comma");
  }
  return spec;
}

std::string FormatChaosSpec(const ChaosSpec& spec) {
  std::ostringstream out;
  out << "drop=" << spec.drop << ",dup=" << spec.dup << ",delay_ms=" << spec.delay_ms
      << ",reorder=" << spec.reorder << ",seed=" << spec.seed << ",channels=" << spec.channels;
  return out.str();
}

ChaosFate DrawChaosFate(const ChaosSpec& spec, std::uint64_t receiver_hash, std::uint64_t channel_hash,
                        std::uint64_t k) {
  ChaosFate fate;
  fate.drop = Uniform(spec.seed, receiver_hash, channel_hash, k, kDrop) < spec.drop;
  fate.duplicate = Uniform(spec.seed, receiver_hash, channel_hash, k, kDuplicate) < spec.dup;
  fate.reorder = Uniform(spec.seed, receiver_hash, channel_hash, k, kReorder) < spec.reorder;
  fate.delay_s = Uniform(spec.seed, receiver_hash, channel_hash, k, kDelay) * spec.delay_ms * 1e-3;
  return fate;
}

std::string FormatChaosCounts(const ChaosCounts& counts) {
  std::ostringstream out;
  out << counts.datagrams << " datagrams: " << counts.dropped << " dropped, " << counts.duplicated
      << " duplicated, " << counts.delayed << " delayed, " << counts.reordered << " reordered";
  return out.str();
}

ChaosQueue::ChaosQueue(const ChaosSpec& spec, const std::string& receiver_name)
    : spec_(spec), regex_(spec.channels), receiver_hash_(Fnv1a64(receiver_name)) {}

bool ChaosQueue::Applies(const std::string& channel) {
  auto it = channels_.find(channel);
  if (it == channels_.end()) {
    if (channels_.size() >= kMaxChannels) return false;
    Channel state;
    state.applies = spec_.active() && std::regex_match(channel, regex_);
    state.hash = Fnv1a64(channel);
    it = channels_.emplace(channel, std::move(state)).first;
  }
  return it->second.applies;
}

void ChaosQueue::Receive(Datagram datagram, double t_s) {
  auto it = channels_.find(datagram.channel);
  if (it == channels_.end() || !it->second.applies) {  // not ours to hurt: due now
    Schedule(std::move(datagram), false, t_s);
    return;
  }
  Channel& channel = it->second;
  const ChaosFate fate = DrawChaosFate(spec_, receiver_hash_, channel.hash, channel.count++);
  ++counts_.datagrams;
  if (fate.drop) {
    ++counts_.dropped;
    Release(&channel, t_s);  // it still arrived: a held datagram waited for it
    return;
  }
  const double due_s = t_s + fate.delay_s;
  if (fate.delay_s > 0) ++counts_.delayed;
  if (fate.duplicate) ++counts_.duplicated;
  if (channel.held) {  // this is the one the held datagram waited for: it goes first
    Schedule(std::move(datagram), fate.duplicate, due_s);
    Release(&channel, due_s);
  } else if (fate.reorder) {
    ++counts_.reordered;
    channel.held = Held{std::move(datagram), fate.duplicate, t_s + kReorderMaxHold_s};
  } else {
    Schedule(std::move(datagram), fate.duplicate, due_s);
  }
}

void ChaosQueue::Schedule(Datagram datagram, bool duplicate, double due_s) {
  if (duplicate) queue_.emplace(std::make_pair(due_s, sequence_++), datagram);
  queue_.emplace(std::make_pair(due_s, sequence_++), std::move(datagram));
}

void ChaosQueue::Release(Channel* channel, double due_s) {
  if (!channel->held) return;
  Held held = std::move(*channel->held);
  channel->held.reset();
  Schedule(std::move(held.datagram), held.duplicate, due_s);
}

std::vector<ChaosQueue::Datagram> ChaosQueue::TakeDue(double t_s) {
  for (auto& [name, channel] : channels_) {
    if (channel.held && channel.held->deadline_s <= t_s) Release(&channel, channel.held->deadline_s);
  }
  std::vector<Datagram> due;
  while (!queue_.empty() && queue_.begin()->first.first <= t_s) {
    due.push_back(std::move(queue_.begin()->second));
    queue_.erase(queue_.begin());
  }
  return due;
}

double ChaosQueue::NextDue() const {
  double next = queue_.empty() ? std::numeric_limits<double>::infinity() : queue_.begin()->first.first;
  for (const auto& [name, channel] : channels_) {
    if (channel.held) next = std::min(next, channel.held->deadline_s);
  }
  return next;
}

}  // namespace orbed
