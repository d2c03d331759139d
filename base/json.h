#pragma once
/// @file
/// The JSON writer of the command-line tools, manifests and results files: a streaming interface
/// over nlohmann::ordered_json (Debian's nlohmann-json3-dev), which does the escaping, the number
/// format and the layout. Keys keep the order they were written in. Non-finite numbers are written
/// as null (JSON has no NaN); text that is not valid UTF-8 has each bad byte replaced by U+FFFD, so
/// the output is always valid JSON. Reading is json_fields.h. Not thread-safe (one writer per
/// document).
///
///   JsonWriter json;
///   json.BeginObject();
///   json.Key("n_used").Int(3);
///   json.Key("translation_m").Array(std::vector<double>{0.1, 0.2, 0.3});
///   json.EndObject();
///   std::cout << json.str() << "\n";   // {"n_used":3,"translation_m":[0.1,0.2,0.3]}
///
/// Numbers are the shortest decimal that reads back to the same double, with nlohmann's ".0" on
/// whole numbers (2.0); integers written with Int() have none.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace orbed {

/// A finite value as the shortest decimal that reads back to it, "null" for NaN and infinities.
std::string JsonNumber(double value);

class JsonWriter {
 public:
  /// indent > 0 pretty-prints with that many spaces per level; 0 writes one line.
  explicit JsonWriter(int indent = 0);
  ~JsonWriter();
  JsonWriter(const JsonWriter&) = delete;
  JsonWriter& operator=(const JsonWriter&) = delete;
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
  /// The document so far (complete once every Begin has its End).
  std::string str() const;

 private:
  // The document and where the writer stands, over nlohmann::ordered_json (json.cc), so that the
  // ~110 k lines of nlohmann do not reach every file that writes JSON.
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace orbed
