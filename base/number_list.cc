#include "base/number_list.h"

#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace orbed {

std::vector<double> ParseNumberList(const std::string& text, const std::string& what) {
  std::vector<double> values;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    size_t used = 0;
    double value = 0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    while (used < item.size() && std::isspace(static_cast<unsigned char>(item[used]))) ++used;
    if (used == 0 || used != item.size() || !std::isfinite(value)) {
      throw std::invalid_argument(what + ": '" + item + "' is not a finite number");
    }
    values.push_back(value);
  }
  if (!text.empty() && text.back() == ',') throw std::invalid_argument(what + ": trailing comma");
  return values;
}

}  // namespace orbed
