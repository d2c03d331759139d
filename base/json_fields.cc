#include "base/json_fields.h"

#include <cmath>
#include <fstream>
#include <limits>

namespace orbed {
namespace {

std::string Describe(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

std::string ChildKey(const std::string& parent, const std::string& name) {
  return parent.empty() ? name : parent + "." + name;
}

}  // namespace

nlohmann::json JsonFields::Parse(const std::string& text, size_t max_bytes, int max_depth) const {
  if (text.size() > max_bytes) {
    throw JsonReadError(source_ + ": " + std::to_string(text.size()) + " bytes, more than the " +
                        std::to_string(max_bytes) + " allowed");
  }
  bool too_deep = false;
  const nlohmann::json::parser_callback_t depth_check = [&](int depth, nlohmann::json::parse_event_t,
                                                            nlohmann::json&) {
    if (depth >= max_depth) too_deep = true;  // depth counts from 0 at the top-level value
    return !too_deep;
  };
  nlohmann::json doc = nlohmann::json::parse(text, depth_check, /*allow_exceptions=*/false);
  if (too_deep) {
    throw JsonReadError(source_ + ": nested deeper than " + std::to_string(max_depth) + " levels");
  }
  if (doc.is_discarded()) throw JsonReadError(source_ + ": not valid JSON");
  return doc;
}

nlohmann::json JsonFields::ReadFile(const std::string& path, size_t max_bytes, int max_depth) const {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw JsonReadError(source_ + ": cannot read " + path);
  std::string text(max_bytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw JsonReadError(source_ + ": cannot read " + path);
  text.resize(static_cast<size_t>(in.gcount()));
  return Parse(text, max_bytes, max_depth);
}

void JsonFields::Fail(const std::string& key, const std::string& expected, const nlohmann::json* got) const {
  throw JsonReadError(source_ + ": " + (key.empty() ? std::string("the document") : key) + ": expected " +
                      expected + (got ? ", got " + Describe(*got) : std::string()));
}

JsonAt JsonFields::Member(const JsonAt& at, const std::string& name) const {
  std::optional<JsonAt> member = OptionalMember(at, name);
  if (!member) Fail(ChildKey(at.key, name), "a value (missing)");
  return *member;
}

std::optional<JsonAt> JsonFields::OptionalMember(const JsonAt& at, const std::string& name) const {
  if (!at.value.is_object()) Fail(at.key, "an object", &at.value);
  const auto it = at.value.find(name);
  if (it == at.value.end() || it->is_null()) return std::nullopt;
  return JsonAt{*it, ChildKey(at.key, name)};
}

std::vector<std::pair<std::string, JsonAt>> JsonFields::Members(const JsonAt& at, size_t max_members) const {
  if (!at.value.is_object()) Fail(at.key, "an object", &at.value);
  if (at.value.size() > max_members) Fail(at.key, "at most " + std::to_string(max_members) + " members");
  std::vector<std::pair<std::string, JsonAt>> members;
  for (auto it = at.value.begin(); it != at.value.end(); ++it) {
    members.emplace_back(it.key(), JsonAt{it.value(), ChildKey(at.key, it.key())});
  }
  return members;
}

size_t JsonFields::ArraySize(const JsonAt& at, size_t max_size) const {
  if (!at.value.is_array()) Fail(at.key, "an array", &at.value);
  if (at.value.size() > max_size)
    Fail(at.key, "an array of at most " + std::to_string(max_size) + " elements");
  return at.value.size();
}

JsonAt JsonFields::Element(const JsonAt& at, size_t index) const {
  if (!at.value.is_array() || index >= at.value.size()) Fail(at.key, "an element " + std::to_string(index));
  return JsonAt{at.value[index], at.key + "[" + std::to_string(index) + "]"};
}

int64_t JsonFields::Integer(const JsonAt& at, int64_t lo, int64_t hi) const {
  const std::string expected = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  int64_t value = 0;
  if (at.value.is_number_unsigned()) {
    const uint64_t u = at.value.get<uint64_t>();
    if (u > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) Fail(at.key, expected, &at.value);
    value = static_cast<int64_t>(u);
  } else if (at.value.is_number_integer()) {
    value = at.value.get<int64_t>();
  } else {
    Fail(at.key, expected, &at.value);
  }
  if (value < lo || value > hi) Fail(at.key, expected, &at.value);
  return value;
}

double JsonFields::Number(const JsonAt& at, double lo, double hi) const {
  const std::string expected = "a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!at.value.is_number()) Fail(at.key, expected, &at.value);
  const double value = at.value.get<double>();
  if (!std::isfinite(value) || value < lo || value > hi) Fail(at.key, expected, &at.value);
  return value;
}

bool JsonFields::Bool(const JsonAt& at) const {
  if (!at.value.is_boolean()) Fail(at.key, "true or false", &at.value);
  return at.value.get<bool>();
}

std::string JsonFields::String(const JsonAt& at, size_t max_bytes) const {
  if (!at.value.is_string()) Fail(at.key, "a string", &at.value);
  const std::string& text = at.value.get_ref<const std::string&>();
  if (text.size() > max_bytes) Fail(at.key, "a string of at most " + std::to_string(max_bytes) + " bytes");
  return text;
}

std::vector<double> JsonFields::Numbers(const JsonAt& at, size_t size, double lo, double hi) const {
  if (!at.value.is_array() || at.value.size() != size) {
    Fail(at.key, "an array of " + std::to_string(size) + " numbers", &at.value);
  }
  std::vector<double> values;
  for (size_t i = 0; i < size; ++i) values.push_back(Number(Element(at, i), lo, hi));
  return values;
}

}  // namespace orbed
