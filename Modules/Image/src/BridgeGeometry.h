#pragma once
// Private to the Image module: ImageGeometry <-> the ITK bridge's plain geometry.
#include "ItkBridge.h"
#include "dynsub/Volume.h"

namespace dynsub {

inline itkbridge::Geometry toBridge(const ImageGeometry& g) {
  itkbridge::Geometry b;
  b.size = g.size;
  for (int a = 0; a < 3; ++a) {
    b.spacing[a] = g.spacing[a];
    b.origin[a] = g.origin[a];
    for (int c = 0; c < 3; ++c) b.direction[3 * a + c] = g.direction(a, c);
  }
  return b;
}

inline ImageGeometry fromBridge(const itkbridge::Geometry& b) {
  ImageGeometry g;
  g.size = b.size;
  for (int a = 0; a < 3; ++a) {
    g.spacing[a] = b.spacing[a];
    g.origin[a] = b.origin[a];
    for (int c = 0; c < 3; ++c) g.direction(a, c) = b.direction[3 * a + c];
  }
  return g;
}

}  // namespace dynsub
