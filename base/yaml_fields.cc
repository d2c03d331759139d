#include "base/yaml_fields.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace orbed {
namespace {

std::string Range(double lo, double hi, const std::string& unit) {
  std::ostringstream s;
  s << "a number";
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi) {
    s << " in [" << lo << ", " << hi << "]";
  } else if (has_lo) {
    s << " >= " << lo;
  } else if (has_hi) {
    s << " <= " << hi;
  }
  if (!unit.empty()) s << " [" << unit << "]";
  return s.str();
}

std::string WithUnit(const std::string& text, const std::string& unit) {
  return unit.empty() ? text : text + " [" + unit + "]";
}

// "a, b or c".
std::string Alternatives(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) {
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  return out;
}

void CollectKeyPaths(const YAML::Node& node, const std::string& prefix, std::set<std::string>* out) {
  if (!node.IsMap()) return;
  for (const auto& kv : node) {
    const std::string name = kv.first.IsScalar() ? kv.first.Scalar() : "(not a word)";
    const std::string path = prefix.empty() ? name : prefix + "." + name;
    out->insert(path);
    CollectKeyPaths(kv.second, path, out);
  }
}

}  // namespace

YAML::Node YamlFields::LoadFile(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw std::runtime_error(path + ": cannot open the file (expected a readable YAML file)");
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
}

YAML::Node YamlFields::LoadString(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
}

YAML::Node YamlFields::LoadDocBlock(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the file (expected a readable source file)");
  std::string line, text;
  int line_number = 0, first_line = 0;
  bool inside = false;
  while (std::getline(in, line)) {
    ++line_number;
    const size_t start = line.find_first_not_of(" \t");
    const std::string trimmed = start == std::string::npos ? "" : line.substr(start);
    if (!inside) {
      if (trimmed == "/// @code{.yaml}") {
        inside = true;
        first_line = line_number + 1;
      }
      continue;
    }
    if (trimmed == "/// @endcode") {
      try {
        return YAML::Load(text);
      } catch (const YAML::Exception& e) {
        throw std::runtime_error(path + ":" + std::to_string(first_line + e.mark.line) +
                                 ": the @code{.yaml} block is not valid YAML: " + e.msg);
      }
    }
    if (trimmed.compare(0, 3, "///") != 0) break;
    text += trimmed.substr(trimmed.size() > 3 && trimmed[3] == ' ' ? 4 : 3) + "\n";
  }
  throw std::runtime_error(path + ": expected a /// @code{.yaml} ... /// @endcode block in a comment");
}

std::set<std::string> YamlFields::KeyPaths(const YAML::Node& node) {
  std::set<std::string> out;
  CollectKeyPaths(node, "", &out);
  return out;
}

void YamlFields::Fail(const YAML::Node& node, const std::string& key, const std::string& expected) const {
  std::string where = source_;
  if (node.IsDefined() && node.Mark().line >= 0) where += ":" + std::to_string(node.Mark().line + 1);
  throw std::runtime_error(where + ": " + key + ": " + expected);
}

void YamlFields::CheckKeys(const YAML::Node& map, const std::string& key,
                           const std::set<std::string>& allowed) const {
  if (!map.IsMap()) Fail(map, key.empty() ? "(top level)" : key, "expected a mapping");
  for (const auto& kv : map) {
    if (!kv.first.IsScalar()) {
      Fail(kv.first, key.empty() ? "(top level)" : key,
           "expected plain words as keys, got a list or mapping");
    }
    const std::string name = kv.first.Scalar();
    if (allowed.count(name)) continue;
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    Fail(kv.first, Join(key, name), "unknown key; expected one of: " + list);
  }
}

YAML::Node YamlFields::Required(const YAML::Node& map, const std::string& name, const std::string& key,
                                const std::string& expected) const {
  const YAML::Node child = map[name];
  if (!child.IsDefined() || child.IsNull()) {
    Fail(map, key, expected.empty() ? "missing (required)" : "missing; expected " + expected);
  }
  return child;
}

YAML::Node YamlFields::Section(const YAML::Node& map, const std::string& name, const std::string& key) const {
  const YAML::Node child = map[name];
  if (!child.IsDefined() || child.IsNull()) return YAML::Node(YAML::NodeType::Map);
  if (!child.IsMap()) Fail(child, key, "expected a mapping");
  return child;
}

double YamlFields::Scalar(const YAML::Node& node, const std::string& key, const std::string& expected) const {
  if (!node.IsScalar()) Fail(node, key, "expected " + expected);
  double v = 0.0;
  try {
    v = node.as<double>();
  } catch (const YAML::Exception&) {
    Fail(node, key, "expected " + expected + ", got '" + node.Scalar() + "'");
  }
  if (!std::isfinite(v)) Fail(node, key, "expected " + expected + ", got '" + node.Scalar() + "'");
  return v;
}

double YamlFields::Number(const YAML::Node& node, const std::string& key, double lo, double hi,
                          const std::string& unit) const {
  const std::string expected = Range(lo, hi, unit);
  const double v = Scalar(node, key, expected);
  if (v < lo || v > hi) Fail(node, key, "expected " + expected + ", got '" + node.Scalar() + "'");
  return v;
}

double YamlFields::NumberOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                            double fallback, double lo, double hi, const std::string& unit) const {
  const YAML::Node child = map[name];
  if (!child.IsDefined()) return fallback;
  return Number(child, Join(prefix, name), lo, hi, unit);
}

double YamlFields::Positive(const YAML::Node& node, const std::string& key, const std::string& unit) const {
  const std::string expected = WithUnit("a number > 0", unit);
  const double v = Scalar(node, key, expected);
  if (!(v > 0)) Fail(node, key, "expected " + expected + ", got '" + node.Scalar() + "'");
  return v;
}

double YamlFields::PositiveOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                              double fallback, const std::string& unit) const {
  const YAML::Node child = map[name];
  if (!child.IsDefined()) return fallback;
  return Positive(child, Join(prefix, name), unit);
}

long long YamlFields::Integer(const YAML::Node& node, const std::string& key, long long lo,
                              long long hi) const {
  const std::string expected = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!node.IsScalar()) Fail(node, key, "expected " + expected);
  long long v = 0;
  try {
    v = node.as<long long>();
  } catch (const YAML::Exception&) {
    Fail(node, key, "expected " + expected + ", got '" + node.Scalar() + "'");
  }
  if (v < lo || v > hi) Fail(node, key, "expected " + expected + ", got '" + node.Scalar() + "'");
  return v;
}

long long YamlFields::IntegerOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                                long long fallback, long long lo, long long hi) const {
  const YAML::Node child = map[name];
  if (!child.IsDefined()) return fallback;
  return Integer(child, Join(prefix, name), lo, hi);
}

bool YamlFields::Bool(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar()) Fail(node, key, "expected true or false");
  try {
    return node.as<bool>();
  } catch (const YAML::Exception&) {
    Fail(node, key, "expected true or false, got '" + node.Scalar() + "'");
  }
}

bool YamlFields::BoolOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                        bool fallback) const {
  const YAML::Node child = map[name];
  if (!child.IsDefined()) return fallback;
  return Bool(child, Join(prefix, name));
}

Eigen::Vector3d YamlFields::Vector3(const YAML::Node& node, const std::string& key,
                                    const std::string& unit) const {
  if (!node.IsSequence() || node.size() != 3)
    Fail(node, key, "expected " + WithUnit("a list of 3 numbers", unit));
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    v[i] = Number(node[i], key + "[" + std::to_string(i) + "]", -INFINITY, INFINITY, unit);
  }
  return v;
}

Eigen::Vector3d YamlFields::PositiveVector3(const YAML::Node& node, const std::string& key,
                                            const std::string& unit) const {
  if (!node.IsSequence() || node.size() != 3) {
    Fail(node, key, "expected " + WithUnit("a list of 3 numbers > 0", unit));
  }
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = Positive(node[i], key + "[" + std::to_string(i) + "]", unit);
  return v;
}

std::string YamlFields::String(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar()) Fail(node, key, "expected a text value");
  return node.Scalar();
}

std::string YamlFields::StringOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                                 const std::string& fallback) const {
  const YAML::Node child = map[name];
  if (!child.IsDefined()) return fallback;
  return String(child, Join(prefix, name));
}

std::string YamlFields::OneOf(const YAML::Node& node, const std::string& key,
                              const std::vector<std::string>& allowed) const {
  if (!node.IsScalar()) Fail(node, key, "expected " + Alternatives(allowed));
  const std::string value = node.Scalar();
  for (const std::string& a : allowed) {
    if (value == a) return value;
  }
  Fail(node, key, "expected " + Alternatives(allowed) + ", got '" + value + "'");
}

std::string YamlFields::OneOfOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                                const std::string& fallback, const std::vector<std::string>& allowed) const {
  const YAML::Node child = map[name];
  if (!child.IsDefined()) return fallback;
  return OneOf(child, Join(prefix, name), allowed);
}

std::vector<std::string> YamlFields::Strings(const YAML::Node& node, const std::string& key) const {
  if (!node.IsSequence() || node.size() == 0) Fail(node, key, "expected a non-empty list of names");
  std::vector<std::string> out;
  for (size_t i = 0; i < node.size(); ++i) {
    if (!node[i].IsScalar()) Fail(node[i], key + "[" + std::to_string(i) + "]", "expected a name");
    out.push_back(node[i].Scalar());
  }
  return out;
}

}  // namespace orbed
