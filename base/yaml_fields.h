#pragma once
/// @file
/// The one checked YAML reader: typed reads for every configuration file of the project (scene,
/// scenario, launch, headset, wearer, SLAM and walk files). Every failure throws std::runtime_error naming the source file, the line, the
/// dotted key and the expected value, e.g.
///   "user.yaml:14: direct_view.depth_bias_fraction_std: expected a number >= 0, got '-1'".
/// Unknown keys are errors (CheckKeys), so that typos in a config are caught, not ignored.
///
/// Threading: a YamlFields is a small immutable helper; use one per load.

#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

namespace orbed {

class YamlFields {
 public:
  /// `source` is the file name (or a label for YAML given as text) used in messages.
  explicit YamlFields(std::string source) : source_(std::move(source)) {}
  const std::string& source() const { return source_; }

  /// Parses a file; throws naming the file when it cannot be read or is not valid YAML.
  static YAML::Node LoadFile(const std::string& path);
  /// Parses text; `source` labels messages.
  static YAML::Node LoadString(const std::string& text, const std::string& source);

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& key, const std::string& expected) const;

  /// Throws unless `map` is a mapping whose keys are all in `allowed`.
  void CheckKeys(const YAML::Node& map, const std::string& key, const std::set<std::string>& allowed) const;
  /// The child `name` of `map`; throws if missing. `key` is the dotted path of the child.
  YAML::Node Required(const YAML::Node& map, const std::string& name, const std::string& key) const;
  /// The child `name` (a mapping) of `map`, or an empty mapping when absent.
  YAML::Node Section(const YAML::Node& map, const std::string& name, const std::string& key) const;

  /// A finite number in [lo, hi]; `unit` is appended to messages (e.g. "m", "deg").
  double Number(const YAML::Node& node, const std::string& key, double lo, double hi,
                const std::string& unit = "") const;
  /// As Number for `map[name]`, or `fallback` when the key is absent.
  double NumberOr(const YAML::Node& map, const std::string& name, const std::string& prefix, double fallback,
                  double lo, double hi, const std::string& unit = "") const;
  /// An integer in [lo, hi].
  long long Integer(const YAML::Node& node, const std::string& key, long long lo, long long hi) const;
  long long IntegerOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                      long long fallback, long long lo, long long hi) const;
  bool BoolOr(const YAML::Node& map, const std::string& name, const std::string& prefix, bool fallback) const;
  /// A list of three finite numbers.
  Eigen::Vector3d Vector3(const YAML::Node& node, const std::string& key, const std::string& unit) const;
  /// A scalar as text (any scalar: names, paths, numbers as written).
  std::string String(const YAML::Node& node, const std::string& key) const;
  /// A non-empty list of scalars.
  std::vector<std::string> Strings(const YAML::Node& node, const std::string& key) const;

 private:
  static std::string Join(const std::string& prefix, const std::string& name) {
    return prefix.empty() ? name : prefix + "." + name;
  }
  std::string source_;
};

}  // namespace orbed
