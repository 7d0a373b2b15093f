#pragma once
// A triangle mesh of the limit surface: each element (LimitSurface.h) is cut
// into N x N parameter squares of two triangles each, at parameters i/N. Samples
// on shared element edges and corners are shared, so a closed control mesh gives
// a closed, consistently oriented triangle mesh (normals point where s_u x s_v
// points: outward for an outward-oriented control mesh).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "dynsub/LimitSurface.h"

namespace dynsub {

struct TriangleSurface {
  MatrixX3 points;   // mm
  MatrixX3 normals;  // unit limit normals at the points
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> triangleElement;           // the element each triangle lies in
  std::vector<ElementType> triangleType;      // that element's type
};

// The tessellation a result is written, voxelized and drawn with: 8 x 8
// squares per face of the control mesh (about 0.2-0.6 mm apart on a fitted
// caudate), i.e. outputSegments() per element.
constexpr int kOutputSegments = 8;
// kOutputSegments halved for each isolation level (at least 2): isolation
// splits each face into 4 or 16 elements, and 8 x 8 squares on each would
// make the surface four or sixteen times as dense as a model's without
// isolation, and as slow to compress and write.
int outputSegments(const LimitSurface& surface);

// Why `segmentsPerElement` squares per element of `surface` are more than
// one surface can number (its triangles past 2^31 - 1), with the largest
// count that fits; empty when they are not.
std::string tessellationTooFine(const LimitSurface& surface, int segmentsPerElement);

// The samples and triangles of `segmentsPerElement` squares per element of
// `surface`, and the bytes tessellate() holds for them: each sample's point
// and normal, each triangle's corners, element and type.
struct TessellationSize {
  std::uint64_t samples = 0, triangles = 0, bytes = 0;
};
TessellationSize tessellationSize(const LimitSurface& surface, int segmentsPerElement);

// N = segmentsPerElement >= 1. Throws dynsub::Error for N < 1 or N > 1024,
// or for a grid tessellationTooFine refuses.
TriangleSurface tessellate(const LimitSurface& surface, const MatrixX3& controlPoints, int segmentsPerElement);

}  // namespace dynsub
