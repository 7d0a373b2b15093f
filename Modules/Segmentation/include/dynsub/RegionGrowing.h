#pragma once
// Regions on a voxel grid, with masks as one byte per voxel in the grid's
// order: the steps of growing a region from a seed (SeedGrowth.h), and the
// boundary points an atlas's carried label gives (Atlas.h).
#include <cstdint>
#include <vector>

#include "dynsub/Volume.h"

namespace dynsub {

// The voxels of `allowed` 6-connected to any of `starts` (which must be allowed).
std::vector<std::uint8_t> connectedTo(const std::vector<std::uint8_t>& allowed, const ImageGeometry& grid,
                                      std::vector<long long> starts);

// The sizes (voxels) of `region`'s 6-connected pieces, largest first.
std::vector<long long> pieceSizes(const std::vector<std::uint8_t>& region, const ImageGeometry& grid);

// Each voxel of `grown`'s distance (mm, exact Euclidean) to the nearest voxel
// outside it; computed once, it serves the cores of every opening.
std::vector<float> depthInside(const std::vector<std::uint8_t>& grown, const ImageGeometry& grid);

// The voxels deeper than `radius` mm inside `grown` (`depth` from
// depthInside): the core of an opening by a ball of that radius.
std::vector<std::uint8_t> coreOf(const std::vector<std::uint8_t>& grown, const std::vector<float>& depth,
                                 double radius);

// The opening of `grown` by a ball of `radius` mm, kept to the part whose
// core (coreOf) is connected to `coreStarts` (core voxels): that core, grown
// back by the same distance inside `grown`. Cuts the thin bridges through
// which like tissue joins a structure to its neighbours.
std::vector<std::uint8_t> openFrom(const std::vector<std::uint8_t>& grown, const std::vector<std::uint8_t>& core,
                                   const ImageGeometry& grid, double radius, std::vector<long long> coreStarts);

// `region` with its holes (what no path from the grid's border through the
// outside reaches) filled.
std::vector<std::uint8_t> fillHoles(const std::vector<std::uint8_t>& region, const ImageGeometry& grid);

// The region's boundary: the midpoints between its voxels and their outside
// 6-neighbours (LPS mm); a voxel on the grid's side counts with its own
// centre, and sets *touchesSide.
std::vector<Vector3> boundaryFaces(const std::vector<std::uint8_t>& region, const ImageGeometry& grid,
                                   bool* touchesSide);

// At most `count` of `points`, spread by farthest-point sampling from the
// one nearest `start`.
std::vector<Vector3> farthestPointSample(const std::vector<Vector3>& points, const Vector3& start, std::size_t count);

}  // namespace dynsub
