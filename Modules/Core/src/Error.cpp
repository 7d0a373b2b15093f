#include "dynsub/Error.h"

namespace dynsub {

Error::Error(const std::string& message) : std::runtime_error(message) {}

Error::Error(const std::string& source, const std::string& message)
    : std::runtime_error(source + ": " + message) {}

}  // namespace dynsub
