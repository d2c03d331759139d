#pragma once
/// @file
/// What the libFuzzer targets share. A process target builds the real process once, on LCM's
/// in-memory provider (memq://), and feeds each input through its subscriptions exactly as the bus
/// would: the first byte picks the channel (channels::kAllChannels, modulo their number), the rest
/// is the datagram. So decode, validation and the handler all run, in-process, per input. A file
/// target hands the input to the parser as the file's text.
///
/// Inputs are also written by `orbed-fuzz-seeds` in this form (one file per logged message).
///
/// Threading: libFuzzer calls LLVMFuzzerTestOneInput on one thread.

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string>

#include "lcmtypes/contract/channels.h"
#include "runtime/flags.h"
#include "runtime/process.h"

namespace orbed::fuzz {

inline constexpr size_t kNumChannels = std::size(channels::kAllChannels);

/// Flags for a process under fuzzing: memq://, warnings and errors only (a million rejections
/// would otherwise fill the terminal).
inline CommonFlags FuzzFlags(const std::string& name) {
  CommonFlags flags(name);
  flags.lcm_url = "memq://";
  flags.log_level = "error";
  ApplyCommonFlags(flags);
  return flags;
}

/// Publishes the input on its channel and dispatches until the in-memory queue is empty (replies a
/// process sends to itself included, at most 64 rounds).
inline void FeedToProcess(Process& process, const uint8_t* data, size_t size) {
  if (size == 0) return;
  const char* channel = channels::kAllChannels[data[0] % kNumChannels];
  process.lcm().publish(channel, data + 1, static_cast<unsigned int>(size - 1));
  for (int round = 0; round < 64 && process.lcm().handleTimeout(0) > 0; ++round) {
  }
}

}  // namespace orbed::fuzz
