#include "base/format.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>

namespace orbed {

std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, value);
  return text;
}

namespace {
template <class Float>
std::string Shortest(Float value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}
}  // namespace

std::string ShortestDecimal(double value) { return Shortest(value); }
std::string ShortestDecimal(float value) { return Shortest(value); }

std::string EscapeText(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const unsigned char byte = static_cast<unsigned char>(c);
    if (byte == '\\') {
      out += "\\\\";
    } else if (byte >= 0x20 && byte < 0x7f) {
      out += c;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", byte);
      out += hex;
    }
  }
  return out;
}

std::string FormatUtc(int64_t utime, const char* format) {
  const std::time_t seconds = static_cast<std::time_t>(utime / 1000000);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  char buffer[64];
  return std::string(buffer, std::strftime(buffer, sizeof(buffer), format, &tm));
}

std::string DescribeErrno(int error_number) {
  const char* name = strerrorname_np(error_number);  // glibc 2.32
  return std::string(std::strerror(error_number)) + " (" + (name ? name : std::to_string(error_number)) + ")";
}

std::string WithStudyColumn(const std::string& csv, int m) {
  std::string out;
  size_t begin = 0;
  bool header = true;
  while (begin < csv.size()) {
    size_t end = csv.find('\n', begin);
    if (end == std::string::npos) end = csv.size();
    if (!header) {
      out += std::to_string(m) + "," + csv.substr(begin, end - begin) + "\n";
    } else if (m == 0) {
      out += "study," + csv.substr(begin, end - begin) + "\n";
    }
    header = false;
    begin = end + 1;
  }
  return out;
}

}  // namespace orbed
