// Unit tests (no rendering): the triangle mesh of the limit surface is closed
// for closed control meshes, consistently oriented and outward.
#include <map>

#include <gtest/gtest.h>

#include "TestMeshes.h"
#include "dynsub/Error.h"
#include "dynsub/Tessellation.h"

namespace {

TEST(Tessellation, ClosedMeshesGiveClosedOutwardSurfaces) {
  for (const auto& [name, mesh] : dynsub::testing::allTestMeshes()) {
    const dynsub::LimitSurface surface(mesh);
    const dynsub::TriangleSurface t = dynsub::tessellate(surface, mesh.points(), 3);
    // Each directed edge once; on a closed mesh its reverse exactly once too.
    std::map<std::pair<int, int>, int> directed;
    for (const auto& tri : t.triangles)
      for (int k = 0; k < 3; ++k) ++directed[{tri[k], tri[(k + 1) % 3]}];
    int unmatched = 0;
    for (const auto& [edge, count] : directed) {
      EXPECT_EQ(count, 1) << name;
      unmatched += directed.count({edge.second, edge.first}) == 0;
    }
    if (mesh.isClosed()) {
      EXPECT_EQ(unmatched, 0) << name;
      // Signed volume (divergence theorem) is positive for outward orientation.
      double volume = 0;
      for (const auto& tri : t.triangles)
        volume += t.points.row(tri[0]).dot(t.points.row(tri[1]).cross(t.points.row(tri[2]))) / 6.0;
      EXPECT_GT(volume, 0.0) << name;
    } else {
      EXPECT_GT(unmatched, 0) << name;
    }
    // Vertex normals agree with the triangles' orientation.
    for (const auto& tri : t.triangles) {
      const dynsub::Vector3 a = t.points.row(tri[0]).transpose();
      const dynsub::Vector3 faceNormal = (t.points.row(tri[1]).transpose() - a).cross(t.points.row(tri[2]).transpose() - a);
      EXPECT_GT(faceNormal.dot(t.normals.row(tri[0]).transpose()), 0.0) << name;
    }
  }
}

TEST(Tessellation, CountsAndBounds) {
  const dynsub::ControlMesh torus = dynsub::testing::makeBumpyTorus();
  const dynsub::LimitSurface surface(torus);
  const dynsub::TriangleSurface t = dynsub::tessellate(surface, torus.points(), 4);
  EXPECT_EQ(t.triangles.size(), 32u * 4 * 4 * 2);
  EXPECT_EQ(t.points.rows(), 32 * 4 * 4);  // a closed quad grid: one sample per square
  EXPECT_THROW(dynsub::tessellate(surface, torus.points(), 0), dynsub::Error);
  EXPECT_THROW(dynsub::tessellate(surface, torus.points(), 1025), dynsub::Error);
  // The size estimate agrees with what is made: each sample's point and
  // normal and a flag, each triangle's corners, element and type.
  const dynsub::TessellationSize size = dynsub::tessellationSize(surface, 4);
  EXPECT_EQ(size.samples, static_cast<std::uint64_t>(t.points.rows()));
  EXPECT_EQ(size.triangles, t.triangles.size());
  EXPECT_EQ(size.bytes, size.samples * 49 + size.triangles * 20);
}

// Past 2^31 - 1 triangles the samples and triangles cannot be numbered:
// refused with the largest count that fits (on 32 elements, 5792 would make
// 2,147,024,896 triangles and 5793 2,147,766,336).
TEST(Tessellation, GridsPastWhatIntCanNumberAreRefused) {
  const dynsub::ControlMesh torus = dynsub::testing::makeBumpyTorus();
  const dynsub::LimitSurface surface(torus);
  EXPECT_EQ(dynsub::tessellationTooFine(surface, 5792), "");
  EXPECT_EQ(dynsub::tessellationTooFine(surface, 5793),
            "5793 samples per face on 32 elements make 2147766336 triangles, more than one surface can number "
            "(2^31 - 1): use at most 5792 samples per face");
}

}  // namespace
