#pragma once
/// @file
/// FlatRow: one decoded message as named cells, for table exports (`orbed-log export --csv`). The
/// generated Flatten functions (orbed/flatten.hpp, from lcmtypes/gen_flatten.py) fill it field by
/// field; column names are field paths with the unit in parentheses when there is one:
///   "utime (us)", "X_WH.position_m[0] (m)", "contacts[1].body_a", "data (bytes)".
///
/// Cells are CSV text (RFC 4180): integers in decimal (int8 as a number, not a character), booleans
/// 1/0, floating point as ShortestDecimal (base/format.h: reads back to the same value; "nan", "inf",
/// "-inf"), strings quoted when they hold a comma, quote, CR or LF or start or end with
/// a space. A byte array is one cell: its length. Pure; not thread-safe (one row per thread).

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "base/format.h"

namespace orbed {
namespace flat {

/// `text` as one CSV cell.
inline std::string CsvCell(const std::string& text) {
  const bool quote = text.find_first_of(",\"\r\n") != std::string::npos ||
                     (!text.empty() && (text.front() == ' ' || text.back() == ' '));
  if (!quote) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

struct FlatRow {
  std::vector<std::string> names;  ///< column names, "path (unit)" or "path"
  std::vector<std::string> cells;  ///< CSV text, one per name

  template <class T>
  void Add(const std::string& path, const char* unit, const T& value) {
    names.push_back(unit[0] != '\0' ? path + " (" + unit + ")" : path);
    if constexpr (std::is_same_v<T, bool>) {
      cells.push_back(value ? "1" : "0");
    } else if constexpr (std::is_floating_point_v<T>) {
      cells.push_back(ShortestDecimal(value));
    } else if constexpr (std::is_integral_v<T>) {
      cells.push_back(std::to_string(static_cast<int64_t>(value)));
    } else {
      cells.push_back(CsvCell(value));
    }
  }
  void AddByteCount(const std::string& path, size_t bytes) {
    names.push_back(path + " (bytes)");
    cells.push_back(std::to_string(bytes));
  }
  void Clear() {
    names.clear();
    cells.clear();
  }
};

}  // namespace flat
}  // namespace orbed
