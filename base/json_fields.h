#pragma once
/// @file
/// The one checked JSON reader, for the JSON files orbed writes and reads back (the logger's
/// manifest.json, the conductor's results.json): bounded parsing and typed reads whose failures
/// throw JsonReadError naming the source, the dotted key and what was expected, e.g.
///   "manifest.json: parts[1].events: expected an integer in [0, 9223372036854775807], got -3".
/// Built on nlohmann::json (Debian's nlohmann-json3-dev), whose parser is iterative; Parse() also
/// refuses text longer than `max_bytes` and nesting deeper than `max_depth`, so a hostile file of n
/// bytes costs O(n) time and memory and a bounded stack.
///
/// Reading: JsonAt is a value with its dotted key; Member() / OptionalMember() / Element() walk
/// down, Integer() / Number() / Bool() / String() read leaves. Unknown members are not errors
/// (the files are written by orbed and may gain keys).
///
/// Threading: a JsonFields is a small immutable helper; the parsed document must outlive every
/// JsonAt taken from it.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace orbed {

class JsonReadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A value of a parsed document and its dotted key ("" for the root).
struct JsonAt {
  const nlohmann::json& value;
  std::string key;
};

class JsonFields {
 public:
  /// `source` names the file (or the text) in messages.
  explicit JsonFields(std::string source) : source_(std::move(source)) {}
  const std::string& source() const { return source_; }

  /// Parses `text`; throws JsonReadError when it is longer than max_bytes, nests deeper than
  /// max_depth or is not one JSON value.
  nlohmann::json Parse(const std::string& text, size_t max_bytes, int max_depth) const;
  /// Reads at most max_bytes of `path` and parses them; throws naming the path when it cannot be
  /// read, is larger, or does not parse.
  nlohmann::json ReadFile(const std::string& path, size_t max_bytes, int max_depth) const;

  [[noreturn]] void Fail(const std::string& key, const std::string& expected,
                         const nlohmann::json* got = nullptr) const;

  /// The member `name` of the object `at`; throws when `at` is not an object or the member is
  /// absent or null.
  JsonAt Member(const JsonAt& at, const std::string& name) const;
  /// The member, or nothing when it is absent or null (`at` must still be an object).
  std::optional<JsonAt> OptionalMember(const JsonAt& at, const std::string& name) const;
  /// The members of an object of at most `max_members`, in the document's (sorted) order.
  std::vector<std::pair<std::string, JsonAt>> Members(const JsonAt& at, size_t max_members) const;
  /// The size of an array of at most `max_size` elements, and its elements.
  size_t ArraySize(const JsonAt& at, size_t max_size) const;
  JsonAt Element(const JsonAt& at, size_t index) const;

  /// An integer in [lo, hi] (a number written without fraction or exponent).
  int64_t Integer(const JsonAt& at, int64_t lo, int64_t hi) const;
  /// A finite number in [lo, hi] (integers included).
  double Number(const JsonAt& at, double lo, double hi) const;
  bool Bool(const JsonAt& at) const;
  /// A string of at most max_bytes.
  std::string String(const JsonAt& at, size_t max_bytes) const;
  /// An array of exactly `size` finite numbers in [lo, hi].
  std::vector<double> Numbers(const JsonAt& at, size_t size, double lo, double hi) const;

 private:
  std::string source_;
};

}  // namespace orbed
