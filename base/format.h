#pragma once
/// @file
/// Number formatting for log lines, tables and reports.
///
/// Threading: pure functions.

#include <string>

namespace orbed {

/// `value` with exactly `digits` decimals ("%.*f"): Fixed(2.345, 1) == "2.3".
std::string Fixed(double value, int digits);

}  // namespace orbed
