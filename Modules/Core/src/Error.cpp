#include "dynsub/Error.h"

#include <cmath>

namespace dynsub {

Error::Error(const std::string& message) : std::runtime_error(message) {}

Error::Error(const std::string& source, const std::string& message)
    : std::runtime_error(source + ": " + message) {}

void requireFiniteNonNegative(double value, const std::string& name) {
  if (!(value >= 0) || !std::isfinite(value))
    throw Error(name + " must be a finite number >= 0 (got " + std::to_string(value) + ")");
}

}  // namespace dynsub
