#pragma once
/// @file
/// Just enough JSON output for the command-line tools, manifests and results files: a streaming
/// writer that handles commas, escaping and non-finite numbers (written as null, since JSON has no
/// NaN). Not a parser. Not thread-safe (one writer per document).
///
///   JsonWriter json;
///   json.BeginObject();
///   json.Key("n_used").Int(3);
///   json.Key("translation_m").Array(std::vector<double>{0.1, 0.2, 0.3});
///   json.EndObject();
///   std::cout << json.str() << "\n";

#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace orbed {

/// Escapes a string for JSON (quotes included in the result).
std::string JsonQuote(const std::string& text);
/// Shortest round-trip decimal for finite values, "null" for NaN and infinities.
std::string JsonNumber(double value);

class JsonWriter {
 public:
  /// indent > 0 pretty-prints with that many spaces per level; 0 writes one line.
  explicit JsonWriter(int indent = 0) : indent_(indent) {}
  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray();
  JsonWriter& EndArray();
  JsonWriter& Key(const std::string& key);
  JsonWriter& String(const std::string& value);
  JsonWriter& Number(double value);
  JsonWriter& Int(int64_t value);
  JsonWriter& Bool(bool value);
  JsonWriter& Null();
  /// The number, or null when there is none.
  JsonWriter& Number(const std::optional<double>& value) { return value ? Number(*value) : Null(); }
  JsonWriter& Array(const std::vector<double>& values);
  JsonWriter& Array(const std::vector<int>& values);
  const std::string str() const { return out_.str(); }

 private:
  void BeforeValue();
  void NewLine();
  std::ostringstream out_;
  int indent_;
  std::vector<bool> first_in_level_;  // one entry per open object/array
  bool after_key_ = false;
};

}  // namespace orbed
