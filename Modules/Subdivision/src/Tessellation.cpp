#include "dynsub/Tessellation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "dynsub/Error.h"
#include "dynsub/Topology.h"

namespace dynsub {

int outputSegments(const LimitSurface& surface) {
  return std::max(2, kOutputSegments >> surface.isolationLevels());
}

std::string tessellationTooFine(const LimitSurface& surface, int segmentsPerElement) {
  // Samples and triangles are numbered by int, as in the surface files'
  // indices: a finer grid than that holds is refused rather than wrapped.
  const int elements = surface.baseTopology().faceCount();
  const std::uint64_t triangles = tessellationSize(surface, segmentsPerElement).triangles;
  if (triangles <= static_cast<std::uint64_t>(std::numeric_limits<int>::max())) return "";
  const int largest = static_cast<int>(std::sqrt(std::numeric_limits<int>::max() / (2.0 * elements)));
  return std::to_string(segmentsPerElement) + " samples per face on " + std::to_string(elements) + " elements make " +
         std::to_string(triangles) + " triangles, more than one surface can number (2^31 - 1): use at most " +
         std::to_string(largest) + " samples per face";
}

TessellationSize tessellationSize(const LimitSurface& surface, int segmentsPerElement) {
  const Topology& base = surface.baseTopology();
  const std::uint64_t n = segmentsPerElement, faces = base.faceCount();
  TessellationSize size;
  size.samples = base.vertexCount() + base.edgeCount() * (n - 1) + faces * (n - 1) * (n - 1);
  size.triangles = 2 * faces * n * n;
  size.bytes = size.samples * (2 * sizeof(Vector3) + sizeof(char)) +
               size.triangles * (sizeof(std::array<int, 3>) + sizeof(int) + sizeof(ElementType));
  return size;
}

TriangleSurface tessellate(const LimitSurface& surface, const MatrixX3& controlPoints, int segmentsPerElement) {
  const int n = segmentsPerElement;
  if (n < 1 || n > 1024) {
    throw Error("samples per face must be between 1 and 1024, got " + std::to_string(n));
  }
  if (const std::string tooFine = tessellationTooFine(surface, n); !tooFine.empty()) throw Error(tooFine);
  const Topology& base = surface.baseTopology();
  // Sample numbering: base vertices, then n-1 per base edge (from its first
  // vertex), then (n-1)^2 per element interior.
  const int edgeBase = base.vertexCount();
  const int interiorBase = edgeBase + base.edgeCount() * (n - 1);
  const int sampleCount = interiorBase + base.faceCount() * (n - 1) * (n - 1);

  // The sample at grid point (i, j) of element f.
  auto sampleId = [&](int f, int i, int j) {
    const Polygon& q = base.face(f);
    if (i == 0 && j == 0) return q[0];
    if (i == n && j == 0) return q[1];
    if (i == n && j == n) return q[2];
    if (i == 0 && j == n) return q[3];
    // Side k of the quad, and the distance from corner k along it.
    int side = -1, along = 0;
    if (j == 0) side = 0, along = i;
    else if (i == n) side = 1, along = j;
    else if (j == n) side = 2, along = n - i;
    else if (i == 0) side = 3, along = n - j;
    if (side < 0) return interiorBase + f * (n - 1) * (n - 1) + (j - 1) * (n - 1) + (i - 1);
    const int e = base.faceEdge(f, side);
    const int fromFirst = base.edgeVertices(e)[0] == q[side] ? along : n - along;
    return edgeBase + e * (n - 1) + fromFirst - 1;
  };

  // An element's (or subpatch's) 16 grid points are blended from the
  // control points once (SurfaceState), not at each of its (n + 1)^2
  // samples; equal to LimitSurface::evaluate to rounding.
  SurfaceState state(surface);
  state.reset(controlPoints);  // checks the control points' count

  TriangleSurface result;
  result.points.setZero(sampleCount, 3);
  result.normals.setZero(sampleCount, 3);
  std::vector<char> done(sampleCount, 0);
  const std::size_t triangleCount = tessellationSize(surface, n).triangles;
  result.triangles.reserve(triangleCount);
  result.triangleElement.reserve(triangleCount);
  result.triangleType.reserve(triangleCount);
  for (int f = 0; f < base.faceCount(); ++f) {
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        const int id = sampleId(f, i, j);
        if (done[id]) continue;
        done[id] = 1;
        const LimitSample sample =
            state.evaluate(ElementPoint{f, static_cast<double>(i) / n, static_cast<double>(j) / n});
        result.points.row(id) = sample.position.transpose();
        result.normals.row(id) = sample.normal.transpose();
      }
    }
    const ElementType type = surface.elementType(f);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const int a = sampleId(f, i, j), b = sampleId(f, i + 1, j);
        const int c = sampleId(f, i + 1, j + 1), d = sampleId(f, i, j + 1);
        result.triangles.push_back({a, b, c});
        result.triangles.push_back({a, c, d});
        for (int t = 0; t < 2; ++t) {
          result.triangleElement.push_back(f);
          result.triangleType.push_back(type);
        }
      }
    }
  }
  return result;
}

}  // namespace dynsub
