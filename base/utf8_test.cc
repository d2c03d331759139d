// FindInvalidUtf8 against RFC 3629's table, byte by byte: every boundary of each sequence length,
// overlong forms, surrogates, code points past U+10FFFF, truncation at the end (the TinyXML case).
#include "base/utf8.h"

#include <string>

#include <gtest/gtest.h>

namespace orbed {
namespace {

constexpr std::size_t kOk = std::string_view::npos;

TEST(Utf8, ValidTextOfEveryLength) {
  EXPECT_EQ(FindInvalidUtf8(""), kOk);
  EXPECT_EQ(FindInvalidUtf8("<robot name='iiwa'/>"), kOk);
  EXPECT_EQ(FindInvalidUtf8("\x7F"), kOk);
  EXPECT_EQ(FindInvalidUtf8("\xC2\x80 \xDF\xBF"), kOk);                          // U+0080, U+07FF
  EXPECT_EQ(FindInvalidUtf8("\xE0\xA0\x80 \xED\x9F\xBF \xEF\xBF\xBF"), kOk);     // U+0800, U+D7FF, U+FFFF
  EXPECT_EQ(FindInvalidUtf8("\xF0\x90\x80\x80 \xF4\x8F\xBF\xBF"), kOk);          // U+10000, U+10FFFF
  EXPECT_EQ(FindInvalidUtf8("Gr\xC3\xBC\xC3\x9F  \xCF\x80 \xE2\x86\x92"), kOk);  // ü ß π →
}

TEST(Utf8, InvalidBytesAreFoundWhereTheyStart) {
  EXPECT_EQ(FindInvalidUtf8(std::string("ab\0c", 4)), 2u);  // NUL
  EXPECT_EQ(FindInvalidUtf8("ab\x80"), 2u);                 // continuation without a lead
  EXPECT_EQ(FindInvalidUtf8("\xC0\xAF"), 0u);               // overlong '/'
  EXPECT_EQ(FindInvalidUtf8("\xC1\xBF"), 0u);               // overlong
  EXPECT_EQ(FindInvalidUtf8("\xE0\x9F\xBF"), 0u);           // overlong 3-byte form of U+07FF
  EXPECT_EQ(FindInvalidUtf8("\xED\xA0\x80"), 0u);           // surrogate U+D800
  EXPECT_EQ(FindInvalidUtf8("\xF0\x8F\xBF\xBF"), 0u);       // overlong 4-byte form of U+FFFF
  EXPECT_EQ(FindInvalidUtf8("\xF4\x90\x80\x80"), 0u);       // U+110000
  EXPECT_EQ(FindInvalidUtf8("\xF5\x80\x80\x80"), 0u);       // lead beyond F4
  EXPECT_EQ(FindInvalidUtf8("\xFF"), 0u);
  EXPECT_EQ(FindInvalidUtf8("x\xC3(y"), 1u);     // second byte not a continuation
  EXPECT_EQ(FindInvalidUtf8("x\xE2\x86y"), 1u);  // third byte not a continuation
  // Truncated at the end: the lead byte that made TinyXML read past the text.
  EXPECT_EQ(FindInvalidUtf8("0 0 \xDC"), 4u);
  EXPECT_EQ(FindInvalidUtf8("\xE2\x86"), 0u);
  EXPECT_EQ(FindInvalidUtf8("ok \xF0\x9F\x98"), 3u);
}

}  // namespace
}  // namespace orbed
