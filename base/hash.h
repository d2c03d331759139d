#pragma once
/// @file
/// The two hashes orbed derives seeds with, defined once: Sebastiano Vigna's SplitMix64 finaliser
/// and the 64-bit FNV-1a hash of a string. Used by the headset's per-trial seeds
/// (hmd_emulator/headset_trial.h) and the fault injection's per-datagram draws
/// (runtime/chaos.h). Changing either moves every seeded number.
///
/// Threading: pure functions.

#include <cstdint>
#include <string>

namespace orbed {

/// SplitMix64's output for state x: x advanced by the golden-ratio increment, then mixed (a
/// bijection of the 64 bits).
std::uint64_t SplitMix64(std::uint64_t x);

/// The 64-bit FNV-1a hash of the bytes of `text` (FNV prime 1099511628211), from the offset basis
/// 1469598103934665603: the standard basis 14695981039346656037 without its last digit. The slip
/// is kept on purpose: every pinned seeded run derives its trial seeds from it. Fnv1a64("") is
/// 0x14650fb0739d0383, not the standard 0xcbf29ce484222325.
std::uint64_t Fnv1a64(const std::string& text);

/// The top 53 bits of `bits` as a uniform number in [0, 1).
inline double UnitInterval(std::uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

}  // namespace orbed
