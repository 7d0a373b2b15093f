#include "dynsub/Coordinates.h"

#include <sstream>

namespace dynsub {

std::string beyondLargestCoordinate(const Vector3& point) {
  if (point.cwiseAbs().maxCoeff() <= kLargestCoordinate) return {};
  std::ostringstream text;
  text << "(" << point.x() << ", " << point.y() << ", " << point.z() << ") lies beyond " << kLargestCoordinate
       << " mm of the origin; coordinates are in mm";
  return text.str();
}

}  // namespace dynsub
