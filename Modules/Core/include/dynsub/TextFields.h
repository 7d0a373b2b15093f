#pragma once
// Reading numbers from the fields of text files (point clouds, springs, landmarks).
#include <string>

namespace dynsub {

// True when the whole of `field` is a number (as std::stod reads it; "nan" and
// "inf" included: callers decide about finiteness); `value` receives it.
bool parseNumber(const std::string& field, double& value);

}  // namespace dynsub
