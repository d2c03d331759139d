#include "base/json.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "base/format.h"

namespace orbed {

std::string JsonNumber(double value) { return std::isfinite(value) ? ShortestDecimal(value) : "null"; }

struct JsonWriter::State {
  int indent;
  nlohmann::ordered_json root;
  std::vector<nlohmann::ordered_json*> open;  // the open objects and arrays, innermost last
  std::string key;                            // the key of the next value in an object

  // Puts `value` where the writer stands (the root, after a Key, or at the end of an array) and
  // returns it there.
  nlohmann::ordered_json& Add(nlohmann::ordered_json value) {
    if (open.empty()) {
      root = std::move(value);
      return root;
    }
    nlohmann::ordered_json& parent = *open.back();
    if (parent.is_array()) {
      parent.push_back(std::move(value));
      return parent.back();
    }
    nlohmann::ordered_json& slot = parent[key];
    slot = std::move(value);
    return slot;
  }
};

JsonWriter::JsonWriter(int indent) : state_(std::make_unique<State>()) { state_->indent = indent; }

JsonWriter::~JsonWriter() = default;

JsonWriter& JsonWriter::BeginObject() {
  state_->open.push_back(&state_->Add(nlohmann::ordered_json::object()));
  return *this;
}

JsonWriter& JsonWriter::EndObject() {
  state_->open.pop_back();
  return *this;
}

JsonWriter& JsonWriter::BeginArray() {
  state_->open.push_back(&state_->Add(nlohmann::ordered_json::array()));
  return *this;
}

JsonWriter& JsonWriter::EndArray() {
  state_->open.pop_back();
  return *this;
}

JsonWriter& JsonWriter::Key(const std::string& key) {
  state_->key = key;
  return *this;
}

JsonWriter& JsonWriter::String(const std::string& value) {
  state_->Add(value);
  return *this;
}

JsonWriter& JsonWriter::Number(double value) {
  state_->Add(std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr));
  return *this;
}

JsonWriter& JsonWriter::Int(int64_t value) {
  state_->Add(value);
  return *this;
}

JsonWriter& JsonWriter::Bool(bool value) {
  state_->Add(value);
  return *this;
}

JsonWriter& JsonWriter::Null() {
  state_->Add(nullptr);
  return *this;
}

JsonWriter& JsonWriter::Array(const std::vector<double>& values) {
  nlohmann::ordered_json array = nlohmann::ordered_json::array();
  for (double v : values) array.push_back(std::isfinite(v) ? nlohmann::ordered_json(v) : nullptr);
  state_->Add(std::move(array));
  return *this;
}

JsonWriter& JsonWriter::Array(const std::vector<int>& values) {
  state_->Add(values);
  return *this;
}

std::string JsonWriter::str() const {
  return state_->root.dump(state_->indent > 0 ? state_->indent : -1, ' ', false,
                           nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace orbed
