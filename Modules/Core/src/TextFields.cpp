#include "dynsub/TextFields.h"

#include <stdexcept>

namespace dynsub {

bool parseNumber(const std::string& field, double& value) {
  try {
    std::size_t used = 0;
    value = std::stod(field, &used);
    return used == field.size();
  } catch (const std::logic_error&) {  // invalid_argument, out_of_range
    return false;
  }
}

}  // namespace dynsub
