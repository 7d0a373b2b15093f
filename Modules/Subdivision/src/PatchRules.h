#pragma once
// Internal building blocks of LimitSurface: the 16-point neighbourhood of a
// regular quad, the uniform bicubic B-spline basis, the limit and tangent masks
// at a vertex, and one step of local subdivision around an extraordinary vertex.
#include <array>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynsub/Topology.h"

namespace dynsub::detail {

// A point as a weighted sum of mesh vertices: (vertex, weight) pairs.
using SmallStencil = std::vector<std::pair<int, double>>;

// Grid slot i + 4 j holds the control point of B-spline index i along u
// (corner 0 -> corner 1) and j along v (corner 0 -> corner 3); the quad is the
// cell between slots (1,1) and (2,2). Missing neighbours across a boundary are
// mirrored ghosts. Returns false unless `face` is a quad with four regular
// corners whose neighbours are quads.
bool gatherRegularPatch(const Topology& topology, int face, std::array<SmallStencil, 16>& grid);

// Rows: s, s_u, s_v, s_uu, s_uv, s_vv; columns: the 16 grid slots.
Eigen::Matrix<double, 6, 16> bsplineWeights(double u, double v);

// The limit position of vertex x and, for an interior or corner vertex, the
// two limit tangents along the edges from x to the next and to the previous
// corner of face f (f contains x; all faces around x are quads). For a boundary
// vertex with >= 2 faces the tangents are left empty: `along` is the exact
// tangent of the boundary curve (towards the first boundary edge), and f spans
// the angles position*pi/faces .. (position+1)*pi/faces of the fan, so the
// caller can blend it with a cross-boundary tangent. See LimitSurface.h.
struct VertexMasks {
  SmallStencil position, tangentU, tangentV;
  bool boundary = false;
  int faces = 0;
  int fanPosition = 0;
  SmallStencil along;
};
VertexMasks vertexMasks(const Topology& topology, int x, int f);

// The faces touching any face at vertex x, renumbered; `face` is f with its
// corners rotated so that x is corner 0; parentVertex maps local to original.
// The faces come as polygons, over parentVertex.size() vertices: neighbourhoods
// of one structure have equal polygons, and a caller that has met the
// structure before reuses its Topology instead of building another.
struct Neighbourhood {
  std::vector<Polygon> faces;
  std::vector<int> parentVertex;
  int face = -1;
};
Neighbourhood extractNeighbourhood(const Topology& topology, int x, int f);

// A neighbourhood whose vertices are blends (rows of `weights`) of a fixed set
// of control vertices, with the extraordinary vertex at corner 0 of `face`.
// The topology is shared: every level of every neighbourhood of one
// structure has the same one.
struct LocalMesh {
  std::shared_ptr<const Topology> topology;
  Eigen::MatrixXd weights;
  int face = -1;
};
// Three regular subpatches of `face` after one local subdivision, children
// 1, 2, 3 (each in its own corner frame), as 16 grid rows over the columns of
// `weights`.
using LevelPatches = std::array<Eigen::Matrix<double, 16, Eigen::Dynamic>, 3>;

// One level of that subdivision as fixed linear maps over the local
// vertices, valid for one local topology (`from`, `face`): the patches are
// patches[k] * weights, the next level's weights next * weights. After a
// level or two around an isolated extraordinary vertex the local topology
// repeats itself, so a step built once serves every deeper level.
struct CornerStep {
  std::shared_ptr<const Topology> from;
  int face = -1;
  std::array<Eigen::MatrixXd, 3> patches;  // 16 by #local vertices
  Eigen::MatrixXd next;                    // #next local vertices by #local vertices
  std::shared_ptr<const Topology> to;
  int toFace = -1;
};
CornerStep cornerStep(std::shared_ptr<const Topology> topology, int face);
// The level's patches of `mesh`; advances it to the next level (the child at
// corner 0). `step` must be cornerStep(mesh.topology, mesh.face), or an
// equal one.
LevelPatches subdivideAroundCorner(LocalMesh& mesh, const CornerStep& step);

// (u, v) in the frame whose origin is corner k of a quad and whose u axis runs
// to corner k+1: k = 0: (u, v); 1: (v, 1-u); 2: (1-u, 1-v); 3: (1-v, u).
std::pair<double, double> cornerFrame(int k, double u, double v);
// d(frame)/d(u, v) of cornerFrame (rows: frame u, frame v).
Eigen::Matrix2d cornerFrameJacobian(int k);

}  // namespace dynsub::detail
