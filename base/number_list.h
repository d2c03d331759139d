#pragma once
/// @file
/// Parses a comma-separated list of finite numbers ("0, 30.5,-60") as given on command lines
/// (--q-deg and the like). Spaces around numbers are allowed; an empty item, a trailing comma, a
/// non-number or a non-finite value throws std::invalid_argument "<what>: '<item>' is not a finite
/// number" (or "... trailing comma"). Pure; thread-safe.

#include <string>
#include <vector>

namespace orbed {

std::vector<double> ParseNumberList(const std::string& text, const std::string& what);

}  // namespace orbed
