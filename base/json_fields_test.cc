// base/json_fields.h: the checked JSON reader reads what JsonWriter writes, and refuses oversized,
// too deeply nested, malformed and mistyped input naming the key.
#include <functional>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "base/json.h"
#include "base/json_fields.h"

namespace orbed {
namespace {

std::string ErrorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const JsonReadError& e) {
    return e.what();
  }
  return "";
}

TEST(JsonFields, ReadsWhatJsonWriterWrites) {
  JsonWriter out(2);
  out.BeginObject();
  out.Key("count").Int(std::numeric_limits<int64_t>::max());
  out.Key("negative").Int(-7);
  out.Key("x").Number(0.1);
  out.Key("whole").Number(3.0);  // written as 3, still a number
  out.Key("ok").Bool(true);
  out.Key("name").String("a \"quoted\"\nname");
  out.Key("xyz").Array(std::vector<double>{1.5, -2.0, 1e-300});
  out.Key("gone").Null();
  out.Key("inner").BeginObject().Key("b").Int(2).Key("a").Int(1).EndObject();
  out.EndObject();

  const JsonFields f("test.json");
  const nlohmann::json doc = f.Parse(out.str(), 1 << 20, 8);
  const JsonAt root{doc, ""};
  EXPECT_EQ(f.Integer(f.Member(root, "count"), 0, std::numeric_limits<int64_t>::max()),
            std::numeric_limits<int64_t>::max());
  EXPECT_EQ(f.Integer(f.Member(root, "negative"), -10, 0), -7);
  EXPECT_EQ(f.Number(f.Member(root, "x"), 0, 1), 0.1);  // shortest round trip: exact
  EXPECT_EQ(f.Number(f.Member(root, "whole"), 0, 10), 3.0);
  EXPECT_TRUE(f.Bool(f.Member(root, "ok")));
  EXPECT_EQ(f.String(f.Member(root, "name"), 100), "a \"quoted\"\nname");
  EXPECT_EQ(f.Numbers(f.Member(root, "xyz"), 3, -10, 10), (std::vector<double>{1.5, -2.0, 1e-300}));
  EXPECT_FALSE(f.OptionalMember(root, "gone"));
  EXPECT_FALSE(f.OptionalMember(root, "absent"));
  const auto members = f.Members(f.Member(root, "inner"), 10);
  ASSERT_EQ(members.size(), 2u);
  EXPECT_EQ(members[0].first, "a");
  EXPECT_EQ(members[0].second.key, "inner.a");
}

TEST(JsonFields, ErrorsNameTheSourceTheKeyAndWhatWasExpected) {
  const JsonFields f("m.json");
  const nlohmann::json doc = f.Parse(R"({"parts": [{"events": -3}, {"events": 1.5}], "s": 5})", 1000, 8);
  const JsonAt root{doc, ""};
  const JsonAt parts = f.Member(root, "parts");
  EXPECT_EQ(ErrorOf([&] { f.Integer(f.Member(f.Element(parts, 0), "events"), 0, 10); }),
            "m.json: parts[0].events: expected an integer in [0, 10], got -3");
  EXPECT_EQ(ErrorOf([&] { f.Integer(f.Member(f.Element(parts, 1), "events"), 0, 10); }),
            "m.json: parts[1].events: expected an integer in [0, 10], got 1.5");
  EXPECT_EQ(ErrorOf([&] { f.Member(root, "nope"); }), "m.json: nope: expected a value (missing)");
  EXPECT_EQ(ErrorOf([&] { f.String(f.Member(root, "s"), 10); }), "m.json: s: expected a string, got 5");
  EXPECT_EQ(ErrorOf([&] { f.ArraySize(parts, 1); }),
            "m.json: parts: expected an array of at most 1 elements");
  EXPECT_EQ(ErrorOf([&] { f.Member(f.Member(root, "s"), "x"); }), "m.json: s: expected an object, got 5");
  EXPECT_NE(ErrorOf([&] { f.Integer(f.Member(root, "s"), 0, 4); }), "");
}

TEST(JsonFields, RefusesOversizedDeepAndMalformedText) {
  const JsonFields f("x.json");
  EXPECT_EQ(ErrorOf([&] { f.Parse(std::string(101, ' '), 100, 8); }),
            "x.json: 101 bytes, more than the 100 allowed");
  EXPECT_EQ(ErrorOf([&] { f.Parse("{\"a\": [1, 2", 100, 8); }), "x.json: not valid JSON");
  EXPECT_EQ(ErrorOf([&] { f.Parse("", 100, 8); }), "x.json: not valid JSON");
  EXPECT_EQ(ErrorOf([&] { f.Parse("{} {}", 100, 8); }), "x.json: not valid JSON");
  // Depth: 8 levels pass, 9 do not; a million levels cost no stack.
  EXPECT_EQ(ErrorOf([&] { f.Parse(std::string(8, '[') + std::string(8, ']'), 100, 8); }), "");
  EXPECT_EQ(ErrorOf([&] { f.Parse(std::string(9, '[') + std::string(9, ']'), 100, 8); }),
            "x.json: nested deeper than 8 levels");
  EXPECT_EQ(ErrorOf([&] { f.Parse(std::string(1000000, '['), 2000000, 8); }),
            "x.json: nested deeper than 8 levels");
  EXPECT_EQ(ErrorOf([&] { f.Parse("[1e999]", 100, 8); }), "x.json: not valid JSON");
  EXPECT_NE(ErrorOf([&] { f.ReadFile("/nonexistent/x.json", 100, 8); }), "");
}

}  // namespace
}  // namespace orbed
