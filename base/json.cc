#include "base/json.h"

#include <cmath>

#include "base/format.h"

namespace orbed {

std::string JsonNumber(double value) { return std::isfinite(value) ? ShortestDecimal(value) : "null"; }

nlohmann::ordered_json& JsonWriter::Add(nlohmann::ordered_json value) {
  if (open_.empty()) {
    root_ = std::move(value);
    return root_;
  }
  nlohmann::ordered_json& parent = *open_.back();
  if (parent.is_array()) {
    parent.push_back(std::move(value));
    return parent.back();
  }
  nlohmann::ordered_json& slot = parent[key_];
  slot = std::move(value);
  return slot;
}

JsonWriter& JsonWriter::BeginObject() {
  open_.push_back(&Add(nlohmann::ordered_json::object()));
  return *this;
}

JsonWriter& JsonWriter::EndObject() {
  open_.pop_back();
  return *this;
}

JsonWriter& JsonWriter::BeginArray() {
  open_.push_back(&Add(nlohmann::ordered_json::array()));
  return *this;
}

JsonWriter& JsonWriter::EndArray() {
  open_.pop_back();
  return *this;
}

JsonWriter& JsonWriter::Key(const std::string& key) {
  key_ = key;
  return *this;
}

JsonWriter& JsonWriter::String(const std::string& value) {
  Add(value);
  return *this;
}

JsonWriter& JsonWriter::Number(double value) {
  Add(std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr));
  return *this;
}

JsonWriter& JsonWriter::Int(int64_t value) {
  Add(value);
  return *this;
}

JsonWriter& JsonWriter::Bool(bool value) {
  Add(value);
  return *this;
}

JsonWriter& JsonWriter::Null() {
  Add(nullptr);
  return *this;
}

JsonWriter& JsonWriter::Array(const std::vector<double>& values) {
  nlohmann::ordered_json array = nlohmann::ordered_json::array();
  for (double v : values) array.push_back(std::isfinite(v) ? nlohmann::ordered_json(v) : nullptr);
  Add(std::move(array));
  return *this;
}

JsonWriter& JsonWriter::Array(const std::vector<int>& values) {
  Add(values);
  return *this;
}

std::string JsonWriter::str() const {
  return root_.dump(indent_ > 0 ? indent_ : -1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace orbed
