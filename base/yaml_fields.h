#pragma once
/// @file
/// The one checked YAML reader: typed reads for every configuration file of the project (scene,
/// scenario, launch, headset, wearer, SLAM and walk files). Every failure throws std::runtime_error
/// naming the source file, the line, the dotted key and the expected value, e.g.
///   "user.yaml:14: user.direct_view.depth_bias_fraction_std: expected a number >= 0, got '-1'".
/// Unknown keys are errors (CheckKeys), so that typos in a config are caught, not ignored.
///
/// Naming: `X(node, key, ...)` reads a node that must be there; `XOr(map, name, prefix, fallback,
/// ...)` reads `map[name]` (dotted key prefix.name) or returns `fallback` when the key is absent.
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
  /// Parses the YAML between the lines `/// @code{.yaml}` and `/// @endcode` of a source file's
  /// comment (a header's documented defaults), the "///" and one space stripped from each line.
  /// Throws naming the file when there is no such block, and the header's line when it is not
  /// valid YAML.
  static YAML::Node LoadDocBlock(const std::string& path);
  /// The dotted paths of every mapping key in `node`, recursing into mappings (a list is a leaf),
  /// e.g. {"slam", "slam.seed", "slam.jitter", "slam.jitter.rotation_std_deg"}.
  static std::set<std::string> KeyPaths(const YAML::Node& node);

  /// Throws "source:line: key: expected" (the line when the node has one).
  [[noreturn]] void Fail(const YAML::Node& node, const std::string& key, const std::string& expected) const;

  /// Throws unless `map` is a mapping whose keys are plain words, all in `allowed`.
  void CheckKeys(const YAML::Node& map, const std::string& key, const std::set<std::string>& allowed) const;
  /// The child `name` of `map`; throws "key: missing (required)" when absent or null, or
  /// "key: missing; expected <expected>" when `expected` is given. `key` is the child's dotted path.
  YAML::Node Required(const YAML::Node& map, const std::string& name, const std::string& key,
                      const std::string& expected = "") const;
  /// The child `name` (a mapping) of `map`, or an empty mapping when absent.
  YAML::Node Section(const YAML::Node& map, const std::string& name, const std::string& key) const;

  /// A finite number in [lo, hi]; `unit` is appended to messages (e.g. "m", "deg").
  double Number(const YAML::Node& node, const std::string& key, double lo, double hi,
                const std::string& unit = "") const;
  double NumberOr(const YAML::Node& map, const std::string& name, const std::string& prefix, double fallback,
                  double lo, double hi, const std::string& unit = "") const;
  /// A finite number > 0 (an open lower bound, no upper bound).
  double Positive(const YAML::Node& node, const std::string& key, const std::string& unit = "") const;
  double PositiveOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                    double fallback, const std::string& unit = "") const;
  /// An integer in [lo, hi].
  long long Integer(const YAML::Node& node, const std::string& key, long long lo, long long hi) const;
  long long IntegerOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                      long long fallback, long long lo, long long hi) const;
  /// true or false (YAML's spellings: true/false, yes/no, on/off).
  bool Bool(const YAML::Node& node, const std::string& key) const;
  bool BoolOr(const YAML::Node& map, const std::string& name, const std::string& prefix, bool fallback) const;
  /// A list of three finite numbers (each > 0 for PositiveVector3); `unit` may be empty.
  Eigen::Vector3d Vector3(const YAML::Node& node, const std::string& key, const std::string& unit) const;
  Eigen::Vector3d PositiveVector3(const YAML::Node& node, const std::string& key,
                                  const std::string& unit) const;
  /// A scalar as text (any scalar: names, paths, numbers as written).
  std::string String(const YAML::Node& node, const std::string& key) const;
  std::string StringOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                       const std::string& fallback) const;
  /// One of `allowed` (an enumeration), e.g. "expected box, cylinder or sphere, got 'cone'".
  std::string OneOf(const YAML::Node& node, const std::string& key,
                    const std::vector<std::string>& allowed) const;
  std::string OneOfOr(const YAML::Node& map, const std::string& name, const std::string& prefix,
                      const std::string& fallback, const std::vector<std::string>& allowed) const;
  /// A non-empty list of scalars.
  std::vector<std::string> Strings(const YAML::Node& node, const std::string& key) const;

 private:
  /// A finite number; failures say `expected`.
  double Scalar(const YAML::Node& node, const std::string& key, const std::string& expected) const;
  static std::string Join(const std::string& prefix, const std::string& name) {
    return prefix.empty() ? name : prefix + "." + name;
  }
  std::string source_;
};

}  // namespace orbed
