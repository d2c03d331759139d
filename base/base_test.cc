// base/: formatting, units, the seed hashes, SHA-256 (FIPS 180-4 vectors), number lists, the JSON
// writer, the checked YAML reader.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/format.h"
#include "base/hash.h"
#include "base/json.h"
#include "base/number_list.h"
#include "base/replace_file.h"
#include "base/sha256.h"
#include "base/units.h"
#include "base/yaml_fields.h"

namespace orbed {
namespace {

TEST(Format, EscapeTextKeepsPrintableAsciiAndHexesTheRest) {
  EXPECT_EQ(EscapeText("run-42 ok"), "run-42 ok");
  EXPECT_EQ(EscapeText(std::string("a\x1b[2Jb\n\0c", 9)), "a\\x1b[2Jb\\x0a\\x00c");
  EXPECT_EQ(EscapeText("back\\slash"), "back\\\\slash");
  EXPECT_EQ(EscapeText("\xc3\xa9"), "\\xc3\\xa9");  // UTF-8 too: bytes from the bus are not trusted text
}

TEST(ReplaceFile, ReplacesWholeAndNamesTheFileWhenItCannot) {
  const std::string path = ::testing::TempDir() + "orbed_replace_file_test.txt";
  std::string error;
  ASSERT_TRUE(ReplaceFile(path, "first version, longer", &error)) << error;
  ASSERT_TRUE(ReplaceFile(path, std::string("second\0", 7), &error)) << error;
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, std::string("second\0", 7));
  EXPECT_FALSE(std::ifstream(path + ".tmp").good());  // the temporary is gone
  std::remove(path.c_str());
  EXPECT_FALSE(ReplaceFile("/nonexistent-dir/x.json", "{}", &error));
  EXPECT_NE(error.find("/nonexistent-dir/x.json.tmp: No such file or directory (ENOENT)"), std::string::npos)
      << error;
}

TEST(Format, DescribeErrnoGivesTheTextAndTheName) {
  EXPECT_EQ(DescribeErrno(ENOSPC), "No space left on device (ENOSPC)");
  EXPECT_EQ(DescribeErrno(EIO), "Input/output error (EIO)");
}

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

TEST(Hash, SplitMix64AndTheProjectsFnv1a) {
  // SplitMix64's published first output for state 0 (x = 0 advanced once).
  EXPECT_EQ(SplitMix64(0), 0xe220a8397b1dcdafULL);
  // FNV-1a from the pinned offset basis (base/hash.h): "" is the basis itself, "a" one round.
  EXPECT_EQ(Fnv1a64(""), 1469598103934665603ULL);
  EXPECT_EQ(Fnv1a64("a"), (1469598103934665603ULL ^ 'a') * 1099511628211ULL);
  EXPECT_EQ(Fnv1a64("a"), 0x44bd8ad473cd9906ULL);
  EXPECT_EQ(UnitInterval(0), 0.0);
  EXPECT_EQ(UnitInterval(~0ULL), 1.0 - 0x1.0p-53);
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

// A file is read in 64 KiB blocks: the million-'a' vector spans 16 of them and a partial one.
TEST(Sha256, FilesInBlocks) {
  const std::string path = ::testing::TempDir() + "/sha256_million_a";
  std::ofstream(path, std::ios::binary) << std::string(1000000, 'a');
  std::string error;
  EXPECT_EQ(Sha256FileHex(path, &error), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  EXPECT_EQ(error, "");
  std::ofstream(path, std::ios::binary | std::ios::trunc);  // empty
  EXPECT_EQ(Sha256FileHex(path), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256FileHex(path + ".missing", &error), "");
  EXPECT_NE(error.find("cannot read"), std::string::npos);
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

TEST(Format, ShortestDecimalReadsBack) {
  EXPECT_EQ(ShortestDecimal(0.1), "0.1");
  EXPECT_EQ(ShortestDecimal(2.0), "2");
  EXPECT_EQ(ShortestDecimal(1e-300), "1e-300");
  EXPECT_EQ(ShortestDecimal(1.0 / 3.0), "0.3333333333333333");  // 16 digits read back exactly
  EXPECT_EQ(std::stod(ShortestDecimal(1.0 / 3.0)), 1.0 / 3.0);
  EXPECT_EQ(ShortestDecimal(0.1f), "0.1");  // the float's own shortest, not 0.10000000149011612
  EXPECT_EQ(ShortestDecimal(std::nan("")), "nan");
  EXPECT_EQ(ShortestDecimal(-std::numeric_limits<double>::infinity()), "-inf");
}

TEST(Json, WritesEscapedCompactJson) {
  JsonWriter json;
  json.BeginObject();
  json.Key("name").String("a\"b\n");
  json.Key("v").Array(std::vector<double>{0.1, 2.0, std::nan("")});
  json.Key("ok").Bool(true);
  json.Key("n").Int(-3);
  json.Key("empty").BeginArray().EndArray();
  json.Key("some").Number(std::optional<double>(1.5));
  json.Key("none").Number(std::optional<double>());
  json.EndObject();
  EXPECT_EQ(json.str(),
            R"({"name":"a\"b\n","v":[0.1,2.0,null],"ok":true,"n":-3,"empty":[],"some":1.5,"none":null})");
}

TEST(Json, EscapesControlBytesAndReplacesBadUtf8) {
  JsonWriter json;
  json.BeginArray().String(std::string("tab\t bell\x07 nul") + '\0').String("caf\xc3\xa9 \xff!").EndArray();
  // Control bytes as JSON escapes (RFC 8259 section 7); valid UTF-8 as is; a byte that is not UTF-8
  // becomes U+FFFD (EF BF BD), so the document stays valid JSON.
  EXPECT_EQ(json.str(), "[\"tab\\t bell\\u0007 nul\\u0000\",\"caf\xc3\xa9 \xef\xbf\xbd!\"]");
}

TEST(Json, PrettyPrintsNestedContainersInOrder) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("z").Int(1);
  json.Key("a").BeginArray().BeginObject().Key("k").Number(std::nan("")).EndObject().EndArray();
  json.EndObject();
  EXPECT_EQ(json.str(), "{\n  \"z\": 1,\n  \"a\": [\n    {\n      \"k\": null\n    }\n  ]\n}");
  EXPECT_EQ(JsonNumber(0.1), "0.1");
  EXPECT_EQ(JsonNumber(-std::numeric_limits<double>::infinity()), "null");
}

// The message of what `read` throws, or "(no error)".
template <class F>
std::string ErrorOf(F read) {
  try {
    read();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(YamlFields, RequiredNamesWhatWasExpected) {
  const YamlFields f("t.yaml");
  const YAML::Node root = YamlFields::LoadString("a: 1\nb:\n", "t.yaml");
  EXPECT_EQ(f.Required(root, "a", "a").as<int>(), 1);
  EXPECT_EQ(ErrorOf([&] { f.Required(root, "b", "x.b"); }), "t.yaml:1: x.b: missing (required)");
  EXPECT_EQ(ErrorOf([&] { f.Required(root, "c", "x.c", "a length > 0 [m]"); }),
            "t.yaml:1: x.c: missing; expected a length > 0 [m]");
}

TEST(YamlFields, PositiveIsAnOpenLowerBound) {
  const YamlFields f("t.yaml");
  const YAML::Node root = YamlFields::LoadString("a: 0.25\nzero: 0\nneg: -1\nword: x\nnan: .nan\n", "t.yaml");
  EXPECT_EQ(f.Positive(root["a"], "a", "m"), 0.25);
  EXPECT_EQ(f.PositiveOr(root, "missing", "p", 3.0, "s"), 3.0);
  EXPECT_EQ(f.PositiveOr(root, "a", "p", 3.0, "s"), 0.25);
  EXPECT_EQ(ErrorOf([&] { f.Positive(root["zero"], "zero", "m"); }),
            "t.yaml:2: zero: expected a number > 0 [m], got '0'");
  EXPECT_EQ(ErrorOf([&] { f.PositiveOr(root, "neg", "p", 1.0); }),
            "t.yaml:3: p.neg: expected a number > 0, got '-1'");
  EXPECT_EQ(ErrorOf([&] { f.Positive(root["word"], "word"); }),
            "t.yaml:4: word: expected a number > 0, got 'x'");
  EXPECT_EQ(ErrorOf([&] { f.Positive(root["nan"], "nan"); }),
            "t.yaml:5: nan: expected a number > 0, got '.nan'");
}

TEST(YamlFields, Vectors) {
  const YamlFields f("t.yaml");
  const YAML::Node root = YamlFields::LoadString("v: [1, -2, 3]\nshort: [1, 2]\n", "t.yaml");
  EXPECT_TRUE(f.Vector3(root["v"], "v", "m").isApprox(Eigen::Vector3d(1, -2, 3)));
  EXPECT_EQ(ErrorOf([&] { f.Vector3(root["short"], "short", ""); }),
            "t.yaml:2: short: expected a list of 3 numbers");
  EXPECT_EQ(ErrorOf([&] { f.PositiveVector3(root["short"], "short", "m"); }),
            "t.yaml:2: short: expected a list of 3 numbers > 0 [m]");
  EXPECT_EQ(ErrorOf([&] { f.PositiveVector3(root["v"], "v", "m"); }),
            "t.yaml:1: v[1]: expected a number > 0 [m], got '-2'");
}

TEST(YamlFields, BoolsTextAndEnumerations) {
  const YamlFields f("t.yaml");
  const YAML::Node root = YamlFields::LoadString(
      "yes_: true\nno_: off\nbad: maybe\nlist: [1]\nshape: cone\nname: bed\n", "t.yaml");
  EXPECT_TRUE(f.Bool(root["yes_"], "yes_"));
  EXPECT_FALSE(f.BoolOr(root, "no_", "", true));
  EXPECT_TRUE(f.BoolOr(root, "absent", "", true));
  EXPECT_EQ(ErrorOf([&] { f.BoolOr(root, "bad", "p", false); }),
            "t.yaml:3: p.bad: expected true or false, got 'maybe'");
  EXPECT_EQ(ErrorOf([&] { f.Bool(root["list"], "list"); }), "t.yaml:4: list: expected true or false");
  EXPECT_EQ(f.StringOr(root, "name", "", "orbed"), "bed");
  EXPECT_EQ(f.StringOr(root, "absent", "", "orbed"), "orbed");
  EXPECT_EQ(ErrorOf([&] { f.StringOr(root, "list", "p", ""); }), "t.yaml:4: p.list: expected a text value");
  const std::vector<std::string> shapes = {"box", "cylinder", "sphere"};
  EXPECT_EQ(f.OneOfOr(root, "absent", "", "box", shapes), "box");
  EXPECT_EQ(ErrorOf([&] { f.OneOf(root["shape"], "o.shape", shapes); }),
            "t.yaml:5: o.shape: expected box, cylinder or sphere, got 'cone'");
  EXPECT_EQ(ErrorOf([&] {
              f.OneOfOr(root, "name", "p", "none", {"heartbeat", "none"});
            }),
            "t.yaml:6: p.name: expected heartbeat or none, got 'bed'");
  EXPECT_EQ(ErrorOf([&] { f.OneOf(root["list"], "list", {"a"}); }), "t.yaml:4: list: expected a");
}

TEST(YamlFields, KeysMustBeKnownPlainWords) {
  const YamlFields f("t.yaml");
  EXPECT_EQ(ErrorOf([&] { f.CheckKeys(YamlFields::LoadString("a: 1\nb: 2\n", "t.yaml"), "m", {"a"}); }),
            "t.yaml:2: m.b: unknown key; expected one of: a");
  EXPECT_EQ(ErrorOf([&] { f.CheckKeys(YamlFields::LoadString("a: 1\n[x]: 2\n", "t.yaml"), "m", {"a"}); }),
            "t.yaml:2: m: expected plain words as keys, got a list or mapping");
  EXPECT_EQ(ErrorOf([&] { f.CheckKeys(YamlFields::LoadString("[1, 2]", "t.yaml"), "", {"a"}); }),
            "t.yaml:1: (top level): expected a mapping");
}

TEST(YamlFields, DocBlockAndKeyPaths) {
  const std::string path = ::testing::TempDir() + "/yaml_fields_doc.h";
  std::ofstream(path)
      << "#pragma once\n/// Defaults:\n/// @code{.yaml}\n/// slam:\n///   seed: 1   # the walk\n"
         "///   jitter: {rotation_std_deg: 0.02}\n///   band: [0.003, 0.014]\n/// @endcode\n";
  const YAML::Node doc = YamlFields::LoadDocBlock(path);
  EXPECT_EQ(doc["slam"]["seed"].as<int>(), 1);
  EXPECT_EQ(YamlFields::KeyPaths(doc), (std::set<std::string>{"slam", "slam.seed", "slam.jitter",
                                                              "slam.jitter.rotation_std_deg", "slam.band"}));
  std::ofstream(path) << "/// @code{.yaml}\n/// a: [1\n/// @endcode\n";
  EXPECT_NE(ErrorOf([&] { YamlFields::LoadDocBlock(path); }).find("yaml_fields_doc.h:"), std::string::npos);
  std::ofstream(path) << "// nothing documented\n";
  EXPECT_NE(ErrorOf([&] { YamlFields::LoadDocBlock(path); }).find("expected a /// @code{.yaml}"),
            std::string::npos);
}

// Studies written one after the other make one CSV: the header once, with `study` first.
TEST(Format, WithStudyColumnLeadsEveryRowWithTheStudy) {
  const std::string csv = "user,mode\nu1,ar\nu2,ar\n";
  EXPECT_EQ(WithStudyColumn(csv, 0), "study,user,mode\n0,u1,ar\n0,u2,ar\n");
  EXPECT_EQ(WithStudyColumn(csv, 7), "7,u1,ar\n7,u2,ar\n");
  EXPECT_EQ(WithStudyColumn("user,mode\n", 3), "");
}

}  // namespace

}  // namespace orbed
