#pragma once
/// @file
/// A gtest helper for tests that compare a run's results.json with a pinned one: walks two parsed
/// JSON (or YAML) trees together and expects the same keys, the same sequence lengths, numbers equal
/// within a relative 1e-9 (the run's arithmetic decides, not the printing), other scalars equal.
/// Keys in `skip` (the times of a run) are not compared, on either side.

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

namespace orbed::testing {

inline void ExpectSameTree(const YAML::Node& expected, const YAML::Node& actual, const std::string& where,
                           const std::set<std::string>& skip) {
  ASSERT_EQ(expected.Type(), actual.Type()) << where;
  if (expected.IsMap()) {
    size_t compared = 0, expected_keys = 0;
    for (const auto& item : actual) compared += skip.count(item.first.as<std::string>()) == 0;
    for (const auto& item : expected) expected_keys += skip.count(item.first.as<std::string>()) == 0;
    EXPECT_EQ(compared, expected_keys) << where << ": a key was added or removed";
    for (const auto& item : expected) {
      const std::string key = item.first.as<std::string>();
      if (skip.count(key)) continue;
      ASSERT_TRUE(actual[key]) << where << "." << key << " missing";
      ExpectSameTree(item.second, actual[key], where + "." + key, skip);
    }
  } else if (expected.IsSequence()) {
    ASSERT_EQ(expected.size(), actual.size()) << where;
    for (size_t i = 0; i < expected.size(); ++i) {
      ExpectSameTree(expected[i], actual[i], where + "[" + std::to_string(i) + "]", skip);
    }
  } else if (expected.IsScalar()) {
    double e = 0, a = 0;
    if (YAML::convert<double>::decode(expected, e) && YAML::convert<double>::decode(actual, a)) {
      EXPECT_NEAR(a, e, 1e-9 * std::max(1.0, std::abs(e))) << where;
    } else {
      EXPECT_EQ(expected.as<std::string>(), actual.as<std::string>()) << where;
    }
  }
}

}  // namespace orbed::testing
