#pragma once
/// @file
/// Number and text formatting for log lines, tables and reports.
///
/// Threading: pure functions.

#include <cstdint>
#include <string>

namespace orbed {

/// `value` with exactly `digits` decimals ("%.*f"): Fixed(2.345, 1) == "2.3".
std::string Fixed(double value, int digits);

/// The shortest decimal that reads back to exactly `value` (std::to_chars): 0.1 → "0.1", 2 → "2",
/// 1e-300 → "1e-300"; "nan", "inf", "-inf" for the rest. For CSV cells and text that must round-trip.
std::string ShortestDecimal(double value);
std::string ShortestDecimal(float value);

/// `text` safe to print on a terminal: printable ASCII as is, a backslash as "\\", every other byte
/// as "\xNN" (so a corrupted id from the bus cannot move the cursor or fake a log line). For text
/// that came from the bus or a file.
std::string EscapeText(const std::string& text);

/// An errno value as its text and its name: ENOSPC → "No space left on device (ENOSPC)" (the
/// number when the C library has no name for it).
std::string DescribeErrno(int error_number);

/// A utime [µs since the Unix epoch] as UTC text by strftime's `format`, e.g. "%Y-%m-%dT%H:%M:%SZ".
std::string FormatUtc(int64_t utime, const char* format);

/// A CSV text with a first column `study` = m on every row; the header row (given `study` first) only
/// for m = 0, so that the texts of studies 0, 1, ... written one after the other make one CSV file.
std::string WithStudyColumn(const std::string& csv, int m);

}  // namespace orbed
