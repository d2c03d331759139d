// DecodeBounded against LCM's own encoder and decoder: every well-formed message passes and
// decodes to itself; every truncation, extension and hostile count is refused before LCM's decode
// runs; and a mutated message that passes is one LCM decodes exactly and re-encodes byte for byte.
#include "lcmtypes/bounded_decode.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include <orbed/all_types.hpp>

// Counts the bytes operator new hands out while g_counting is set (this test binary only). A
// sanitizer runtime brings its own operator new: there the counts stay 0 and the sanitizer's
// allocator limits stand in for the bound.
#if defined(__SANITIZE_ADDRESS__)
#define ORBED_COUNT_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ORBED_COUNT_ALLOCATIONS 0
#endif
#endif
#ifndef ORBED_COUNT_ALLOCATIONS
#define ORBED_COUNT_ALLOCATIONS 1
#endif

namespace {
std::atomic<bool> g_counting{false};
std::atomic<size_t> g_allocated_bytes{0};
}  // namespace

#if ORBED_COUNT_ALLOCATIONS
// GCC sees malloc behind operator new and free behind delete, and warns at every inlined pair.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(size_t bytes) {
  if (g_counting) g_allocated_bytes += bytes;
  if (void* p = std::malloc(bytes == 0 ? 1 : bytes)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
#endif

namespace orbed {
namespace {

using Bytes = std::vector<uint8_t>;
using wire::WireError;

template <class Msg>
Bytes Encode(const Msg& msg) {
  Bytes bytes(static_cast<size_t>(msg.getEncodedSize()));
  EXPECT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

// Bytes allocated by DecodeBounded<Msg> on `bytes`, and its result.
template <class Msg>
DecodeResult CountedDecode(const Bytes& bytes, size_t* allocated) {
  Msg msg;
  g_allocated_bytes = 0;
  g_counting = true;
  DecodeResult result = DecodeBounded(bytes.data(), bytes.size(), &msg);
  g_counting = false;
  *allocated = g_allocated_bytes;
  return result;
}

// The properties every encoded message must have; `label` names it in failures.
template <class Msg>
void ExpectBoundedAndExact(const Msg& original, const char* label) {
  SCOPED_TRACE(label);
  const Bytes bytes = Encode(original);
  Msg decoded;
  ASSERT_TRUE(DecodeBounded(bytes.data(), bytes.size(), &decoded).ok());
  EXPECT_EQ(Encode(decoded), bytes);
  // Every proper prefix is refused (LCM's decode would read past it or stop short).
  for (size_t n = 0; n < bytes.size(); ++n) {
    Bytes prefix(bytes.begin(), bytes.begin() + static_cast<long>(n));
    EXPECT_FALSE(CheckEncoding<Msg>(prefix.data(), prefix.size()).ok()) << n << " of " << bytes.size();
  }
  Bytes longer = bytes;
  longer.push_back(0);
  EXPECT_EQ(CheckEncoding<Msg>(longer.data(), longer.size()).kind, WireError::kTrailing);
  Bytes wrong_type = bytes;
  wrong_type[3] ^= 0x10;
  EXPECT_EQ(CheckEncoding<Msg>(wrong_type.data(), wrong_type.size()).kind, WireError::kFingerprint);

  // Random mutations (bit flips, bytes set to extremes, bytes cut or inserted): whatever passes
  // the walk is exactly one message for LCM too, and costs memory linear in its size.
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 4000; ++trial) {
    Bytes mutated = bytes;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits && !mutated.empty(); ++e) {
      const size_t at = rng() % mutated.size();
      switch (rng() % 5) {
        case 0:
          mutated[at] ^= static_cast<uint8_t>(1u << (rng() % 8));
          break;
        case 1:
          mutated[at] = 0xff;
          break;
        case 2:
          mutated[at] = 0x7f;
          break;
        case 3:
          mutated.erase(mutated.begin() + static_cast<long>(at));
          break;
        default:
          mutated.insert(mutated.begin() + static_cast<long>(at), static_cast<uint8_t>(rng()));
      }
    }
    size_t allocated = 0;
    const DecodeResult result = CountedDecode<Msg>(mutated, &allocated);
    // A std::string or vector slot per encoded byte at worst, plus the reason text.
    EXPECT_LE(allocated, 64 * mutated.size() + 4096) << "trial " << trial;
    if (result.ok()) {
      Msg again;
      ASSERT_EQ(again.decode(mutated.data(), 0, static_cast<int>(mutated.size())),
                static_cast<int>(mutated.size()));
      EXPECT_EQ(Encode(again), mutated) << "trial " << trial;
    } else {
      EXPECT_NE(result.kind, WireError::kDecode) << result.error;
      EXPECT_FALSE(result.error.empty());
    }
  }
}

#define ORBED_EXPECT_DEFAULT_TYPE(type) ExpectBoundedAndExact(orbed::type{}, #type);

TEST(BoundedDecodeTest,
     EveryTypeAtItsDefaultPassesAndRefusesDamage){ORBED_FOR_EACH_LCM_TYPE(ORBED_EXPECT_DEFAULT_TYPE)}

process_status_t StatusWithReasons() {
  process_status_t status{};
  status.utime = 1700000000000000;
  status.name = "orbed-registration";
  status.pid = 4242;
  status.state = process_status_t::STATE_RUNNING;
  status.reject_reason = {"ALIGNMENT_TRIAL/decode/count", "SESSION_CONTROL/session"};
  status.reject_count = {3, 1};
  status.num_reasons = 2;
  status.last_error = "bad session id";
  status.dropped = 7;
  status.drop_reason = {"timer/tick", "HMD_CAMERA/busy"};
  status.drop_count = {2, 5};
  status.num_drop_reasons = 2;
  return status;
}

TEST(BoundedDecodeTest, FilledMessagesWithStringsStructsAndMatrices) {
  ExpectBoundedAndExact(StatusWithReasons(), "process_status_t");

  collision_status_t collision{};
  collision.num_contacts = 2;
  collision.contacts.resize(2);
  collision.contacts[0].body_a = "iiwa_link_5";
  collision.contacts[0].body_b = "iiwa_link_7";
  collision.contacts[1].body_a = "table";
  collision.contacts[1].body_b = "iiwa_link_7";
  collision.num_links = 3;
  collision.link_names = {"iiwa_link_1", "iiwa_link_2", ""};
  collision.link_clearance_m = {0.1, 0.2, 0.3};
  ExpectBoundedAndExact(collision, "collision_status_t");

  landmark_request_t landmark{};
  landmark.num_rays = 2;
  landmark.origin_W_m = {{0, 0, 1.6}, {0.5, 0, 1.6}};
  landmark.direction_W = {{1, 0, 0}, {0, 1, 0}};
  ExpectBoundedAndExact(landmark, "landmark_request_t");

  image_t image{};
  image.num_bytes = 300;
  image.data.assign(300, 0x5a);
  ExpectBoundedAndExact(image, "image_t");
}

// The report that started this: a PROCESS_STATUS of a few dozen bytes claiming 2^31 - 1 reasons
// made every subscriber allocate gigabytes. Now it is a counted refusal that allocates next to
// nothing.
TEST(BoundedDecodeTest, AHugeCountIsRefusedBeforeAnyAllocation) {
  process_status_t status{};
  status.name = "x";
  Bytes bytes = Encode(status);
  // num_reasons sits just before last_error ("" = int32 length 1 + the NUL byte), dropped (int64),
  // num_drop_reasons (int32) and host (contract change 9; "" as last_error): 4 + 5 + 8 + 4 + 5
  // bytes from the end.
  const size_t count_at = bytes.size() - 26;
  // 23: one more than the 22 bytes left after the count.
  for (const uint32_t count : {0x7fffffffu, 0x80000000u, 0xffffffffu, 23u}) {
    SCOPED_TRACE(count);
    for (int i = 0; i < 4; ++i)
      bytes[count_at + static_cast<size_t>(i)] = static_cast<uint8_t>(count >> (24 - 8 * i));
    size_t allocated = 0;
    const DecodeResult result = CountedDecode<process_status_t>(bytes, &allocated);
    EXPECT_EQ(result.kind, WireError::kCount) << result.error;
    EXPECT_NE(result.error.find("process_status_t.reject_reason"), std::string::npos) << result.error;
    EXPECT_LT(allocated, 1024u);
  }
}

TEST(BoundedDecodeTest, StringLengthsMustBePositiveAndNulTerminated) {
  process_status_t status{};
  status.name = "ab";
  Bytes bytes = Encode(status);
  // name: int32 length at byte 16 (after fingerprint and utime), value 3 ("ab" + NUL).
  ASSERT_EQ(bytes[19], 3);
  Bytes zero = bytes;
  zero[19] = 0;
  EXPECT_EQ(CheckEncoding<process_status_t>(zero.data(), zero.size()).kind, WireError::kString);
  Bytes negative = bytes;
  negative[16] = 0xff;
  EXPECT_EQ(CheckEncoding<process_status_t>(negative.data(), negative.size()).kind, WireError::kString);
  Bytes unterminated = bytes;
  unterminated[22] = 'c';
  EXPECT_EQ(CheckEncoding<process_status_t>(unterminated.data(), unterminated.size()).kind,
            WireError::kString);
  Bytes embedded = bytes;
  embedded[20] = 0;  // LCM would decode "\0b" and encode "": not one message
  EXPECT_EQ(CheckEncoding<process_status_t>(embedded.data(), embedded.size()).kind, WireError::kString);
}

TEST(BoundedDecodeTest, ReaderSignExtendsEachWidth) {
  const uint8_t bytes[] = {0xff, 0xff, 0xfe, 0x80, 0x00, 0x00, 0x00};
  wire::WireReader reader(bytes, sizeof(bytes));
  int64_t value = 0;
  ASSERT_TRUE(reader.ReadInteger(2, &value, "a"));
  EXPECT_EQ(value, -1);
  ASSERT_TRUE(reader.ReadInteger(1, &value, "b"));
  EXPECT_EQ(value, -2);
  ASSERT_TRUE(reader.ReadInteger(4, &value, "c"));
  EXPECT_EQ(value, INT32_MIN);
  EXPECT_FALSE(reader.ReadInteger(1, &value, "d"));
  EXPECT_EQ(reader.kind(), WireError::kTruncated);
  EXPECT_NE(reader.error().find("d: needs 1 bytes at byte 7 of 7"), std::string::npos) << reader.error();
}

}  // namespace
}  // namespace orbed
