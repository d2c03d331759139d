// base/: formatting, units, SHA-256 (FIPS 180-4 vectors), number lists, the JSON writer.
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/format.h"
#include "base/json.h"
#include "base/number_list.h"
#include "base/sha256.h"
#include "base/units.h"

namespace orbed {
namespace {

TEST(Format, FixedRoundsToTheGivenDecimals) {
  EXPECT_EQ(Fixed(2.345, 1), "2.3");
  EXPECT_EQ(Fixed(-0.5, 0), "-0");  // printf's round-half-even of the binary value
  EXPECT_EQ(Fixed(16.5, 2), "16.50");
  EXPECT_EQ(Fixed(1e6, 0), "1000000");
}

TEST(Units, DegreesAndRadians) {
  EXPECT_DOUBLE_EQ(180.0 * kDegToRad, std::acos(-1.0));
  EXPECT_DOUBLE_EQ(std::acos(-1.0) / 2 * kRadToDeg, 90.0);
  EXPECT_DOUBLE_EQ(kDegToRad * kRadToDeg, 1.0);
}


// FIPS 180-4 example vectors.
TEST(Sha256, KnownVectors) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(NumberList, ParsesAndRejectsWithTheItem) {
  EXPECT_EQ(ParseNumberList("0, 30.5,-60 ", "--q-deg"), (std::vector<double>{0, 30.5, -60}));
  EXPECT_EQ(ParseNumberList("", "x"), std::vector<double>{});
  for (const char* bad : {"1,,2", "1,x", "1,2,", "1,nan", "1,inf", "1,2abc"}) {
    EXPECT_THROW(ParseNumberList(bad, "--q-deg"), std::invalid_argument) << bad;
  }
  try {
    ParseNumberList("1,abc", "--q-deg");
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--q-deg: 'abc' is not a finite number");
  }
}

TEST(Json, WritesEscapedCompactJson) {
  JsonWriter json;
  json.BeginObject();
  json.Key("name").String("a\"b\n");
  json.Key("v").Array(std::vector<double>{0.1, 2.0, std::nan("")});
  json.Key("ok").Bool(true);
  json.Key("n").Int(-3);
  json.Key("empty").BeginArray().EndArray();
  json.EndObject();
  EXPECT_EQ(json.str(), R"({"name":"a\"b\n","v":[0.1,2,null],"ok":true,"n":-3,"empty":[]})");
}

}  // namespace
}  // namespace orbed
