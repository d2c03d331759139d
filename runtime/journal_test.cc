// runtime/journal.h: records written are read back byte for byte; a torn last record (what a
// SIGKILL leaves) ends the readable part and is cut off before appending; damaged, oversized and
// hostile bytes are refused without reading past them.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/session_control_t.hpp>

#include "lcmtypes/bounded_decode.h"
#include "runtime/journal.h"

namespace orbed {
namespace {

namespace fs = std::filesystem;

std::string TempPath(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("orbed_journal_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

JournalRecord Record(const std::string& channel, const std::string& data) {
  return JournalRecord{channel, std::vector<uint8_t>(data.begin(), data.end())};
}

JournalContents Parse(const std::string& bytes, const JournalLimits& limits = {}) {
  return ParseJournal(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), limits);
}

std::string Encode(const JournalRecord& r) {
  return EncodeJournalRecord(r.channel, r.data.data(), r.data.size());
}

TEST(Journal, TheFormatIsAsDocumented) {
  const std::string bytes = Encode(Record("AB", "xyz"));
  ASSERT_EQ(bytes.size(), 20u + 2 + 3);
  EXPECT_EQ(bytes.substr(0, 4), "ORJ1");
  EXPECT_EQ(bytes.substr(4, 8), std::string("\0\0\0\x02\0\0\0\x03", 8));
  // The checksum: the first 8 bytes of SHA-256("ABxyz") (Python's hashlib: 375bf5509fcaf74f).
  EXPECT_EQ(bytes.substr(12, 8), std::string("\x37\x5b\xf5\x50\x9f\xca\xf7\x4f", 8));
  EXPECT_EQ(bytes.substr(20), "ABxyz");
  const JournalContents c = Parse(bytes);
  ASSERT_EQ(c.records.size(), 1u);
  EXPECT_EQ(c.valid_bytes, bytes.size());
  EXPECT_EQ(c.damage, "");
}

TEST(Journal, AppendedRecordsReadBackAndMessagesDecode) {
  const std::string path = TempPath("append.journal");
  fs::remove(path);
  orbed::session_control_t start{};
  start.utime = 42;
  start.session_id = "run-ar";
  start.command = orbed::session_control_t::START;
  {
    Journal journal(path);
    EXPECT_TRUE(journal.contents().records.empty());  // a missing file is an empty journal
    ASSERT_TRUE(journal.Append(MakeJournalRecord("SESSION_CONTROL", start)));
    ASSERT_TRUE(journal.Append(Record("X", std::string(1000, '\xff'))));
  }
  Journal again(path);
  ASSERT_EQ(again.contents().records.size(), 2u);
  EXPECT_EQ(again.contents().damaged_bytes, 0u);
  const JournalRecord& first = again.contents().records[0];
  EXPECT_EQ(first.channel, "SESSION_CONTROL");
  orbed::session_control_t decoded;
  ASSERT_TRUE(DecodeBounded(first.data.data(), first.data.size(), &decoded).ok());
  EXPECT_EQ(decoded.session_id, "run-ar");
  EXPECT_EQ(decoded.utime, 42);
  EXPECT_EQ(again.contents().records[1].data, std::vector<uint8_t>(1000, 0xff));
}

TEST(Journal, ATornLastRecordIsDamageAndIsCutBeforeAppending) {
  const std::string path = TempPath("torn.journal");
  const std::string whole = Encode(Record("A", "first")) + Encode(Record("B", "second"));
  const std::string third = Encode(Record("C", "third"));
  // Every cut inside the third record leaves the first two readable and the rest as damage.
  for (size_t cut = 1; cut < third.size(); ++cut) {
    const JournalContents c = Parse(whole + third.substr(0, cut));
    ASSERT_EQ(c.records.size(), 2u) << cut;
    EXPECT_EQ(c.valid_bytes, whole.size()) << cut;
    EXPECT_EQ(c.damaged_bytes, cut) << cut;
    EXPECT_NE(c.damage, "") << cut;
  }
  WriteBytes(path, whole + third.substr(0, 7));
  {
    Journal journal(path);
    EXPECT_EQ(journal.contents().records.size(), 2u);
    EXPECT_EQ(FileBytes(path), whole);  // the torn bytes are gone before anything is appended
    ASSERT_TRUE(journal.Append(Record("D", "fourth")));
  }
  const JournalContents c = ReadJournal(path);
  ASSERT_EQ(c.records.size(), 3u);
  EXPECT_EQ(c.records[2].channel, "D");
  EXPECT_EQ(c.damaged_bytes, 0u);
}

TEST(Journal, DamageEndsTheReadablePart) {
  const std::string a = Encode(Record("A", "alpha"));
  const std::string b = Encode(Record("B", "beta"));
  const std::string c = Encode(Record("C", "gamma"));
  // A flipped bit anywhere in the second record: only the first is read, never the third.
  for (size_t i = 0; i < b.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::string bad = b;
      bad[i] = static_cast<char>(bad[i] ^ (1 << bit));
      const JournalContents contents = Parse(a + bad + c);
      ASSERT_EQ(contents.records.size(), 1u) << "byte " << i << " bit " << bit;
      EXPECT_EQ(contents.valid_bytes, a.size());
      EXPECT_EQ(contents.damaged_bytes, bad.size() + c.size());
    }
  }
  EXPECT_EQ(Parse(a + "garbage").damage,
            "a record header cut short (7 bytes) at byte " + std::to_string(a.size()));
  EXPECT_EQ(Parse(std::string(40, 'x')).damage, "no record magic at byte 0");
}

TEST(Journal, LengthsAreBoundedBeforeAnythingIsAllocated) {
  JournalLimits limits;
  limits.max_data_bytes = 100;
  limits.max_channel_bytes = 8;
  EXPECT_EQ(Parse(Encode(Record("A", std::string(100, 'x'))), limits).records.size(), 1u);
  EXPECT_EQ(Parse(Encode(Record("A", std::string(101, 'x'))), limits).damage, "data length 101 at byte 0");
  EXPECT_EQ(Parse(Encode(Record("NINECHARS", "x")), limits).damage, "channel length 9 at byte 0");
  // A header claiming 4 GiB of data in a 30-byte file.
  std::string huge = Encode(Record("A", "x"));
  huge.replace(8, 4, std::string("\xff\xff\xff\xff", 4));
  EXPECT_EQ(Parse(huge).damage, "data length 4294967295 at byte 0");
  // Random bytes never crash the reader and never yield a record without its checksum.
  std::mt19937 rng(7);
  for (int i = 0; i < 2000; ++i) {
    std::string bytes = "ORJ1";
    const int n = static_cast<int>(rng() % 64);
    for (int k = 0; k < n; ++k) bytes.push_back(static_cast<char>(rng()));
    EXPECT_TRUE(Parse(bytes).records.empty());
  }
}

TEST(Journal, FilesLargerThanTheLimitAreReadUpToIt) {
  const std::string path = TempPath("large.journal");
  const std::string record = Encode(Record("A", std::string(50, 'x')));
  WriteBytes(path, record + record + record);
  JournalLimits limits;
  limits.max_file_bytes = 2 * record.size() + 10;
  const JournalContents c = ReadJournal(path, limits);
  EXPECT_EQ(c.records.size(), 2u);
  EXPECT_EQ(c.damaged_bytes, record.size());
  EXPECT_NE(c.damage, "");
  // And an append that would outgrow the limit is refused: the file must stay readable whole.
  WriteBytes(path, record);
  Journal journal(path, limits);
  EXPECT_TRUE(journal.Append(Record("A", std::string(50, 'x'))));
  EXPECT_FALSE(journal.Append(Record("A", std::string(50, 'x'))));
  EXPECT_NE(journal.error().find("full"), std::string::npos);
}

TEST(Journal, ReplaceWritesAWholeNewFile) {
  const std::string path = TempPath("replace.journal");
  fs::remove(path);
  Journal journal(path);
  ASSERT_TRUE(journal.Append(Record("A", "1")));
  ASSERT_TRUE(journal.Append(Record("A", "2")));
  ASSERT_TRUE(journal.Replace({Record("S", "start")}));
  ASSERT_TRUE(journal.Append(Record("T", "trial")));
  const JournalContents c = ReadJournal(path);
  ASSERT_EQ(c.records.size(), 2u);
  EXPECT_EQ(c.records[0].channel, "S");
  EXPECT_EQ(c.records[1].channel, "T");
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  std::string error;
  EXPECT_FALSE(WriteJournalFile("/nonexistent-dir/x.journal", {}, &error));
  EXPECT_NE(error.find("/nonexistent-dir/x.journal"), std::string::npos);
}

}  // namespace
}  // namespace orbed
