#include "base/format.h"

#include <cstdio>

namespace orbed {

std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, value);
  return text;
}

}  // namespace orbed
