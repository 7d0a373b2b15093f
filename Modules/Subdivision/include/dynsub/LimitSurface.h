#pragma once
// The exact limit surface s = J p of a Catmull-Clark control mesh of any
// topology (TVCG 1998 §2.2-2.4; ICCV 1998 §2.1-2.3), as values and as sparse
// linear operators over the control vertices.
//
// Creases (Topology.h, CatmullClark.h). Semi-sharp creases are refined away
// first (ceil of the largest sharpness below kInfiniteSharpness global steps,
// at most 4); the mesh is then cut along its sharp creases, one vertex per
// sector (Topology::sharpSectors), so that they are boundaries whose rules are
// the crease rules (the configurations checkCreases in MeshCheck.h accepts).
//
// Isolation (TVCG §2.4.2). While the mesh has a face that is not a quad, or a
// quad with more than one irregular vertex, it is refined globally (at most
// twice). The quads of the result, the *base mesh*, are the elements:
//  - a normal element has four regular corners (Topology::isRegularVertex): one
//    bicubic B-spline patch over its 16-vertex neighbourhood; across a boundary
//    the missing neighbours are mirrored ghosts (2 b - i), which reproduces the
//    boundary rules of CatmullClark.h exactly (a corner ghost is 4c - 2b1 - 2b2 + d);
//  - a special element has one irregular corner (an extraordinary vertex, inside
//    or on the boundary). It is the infinite family of B-spline patches of TVCG
//    §2.3 / §3.1.2: local subdivision of its neighbourhood n times leaves the
//    point in one of three regular subpatches of size 2^-n, with n finite for
//    every (u, v) != the extraordinary corner. Nothing is truncated; the first
//    24 levels are tabulated when first needed, deeper ones computed on demand.
//    At the extraordinary vertex itself: the exact limit position mask, and
//    tangents (interior: the masks of Halstead et al. 1993; boundary: the
//    boundary curve's tangent, and across it the limit direction of the local
//    subdivision's top eigenvector, exact to ~1e-7 rad at any number of
//    faces). There the
//    parameterization is singular (|s_u| -> 0 for valence 3, -> infinity for
//    valence >= 5), so s_u and s_v are the tangent-mask vectors, scaled to equal
//    the B-spline derivatives at a regular vertex; they span the exact tangent
//    plane and give the exact normal; second derivatives there are returned as 0.
//
// Parameters. An element is a quad (c0, c1, c2, c3) of the base mesh with
// (u, v) in [0,1]^2: c0 at (0,0), c1 at (1,0), c2 at (1,1), c3 at (0,1); so
// s_u x s_v points to the side from which the corners run counter-clockwise
// (outward for an outward-oriented mesh). A SurfacePoint names a point by the
// control mesh's own *parametric faces* (Ptex numbering): a quad is one
// parametric face with the same convention; an n-gon is n of them, the k-th
// being the quad (corner k, midpoint of edge k, centre, midpoint of edge k-1).
// Derivatives are taken with respect to the parameters of the point's kind.
//
// Free basis (hierarchical refinement, Simulation.h's RefineRegion): with a
// basis T (#mesh vertices by m), the mesh's points are T q for m free points
// q, and the surface is built over q: every operator's columns, and every
// `controlPoints` argument, are the free points, and controlVertexCount() is
// m. The elements are still the mesh's.
//
// Cost: construction is O(#control vertices); a special element tabulates
// each level of its subpatches the first time a point needs it (thread-safe),
// so evaluating a point is O(1) after the first one at its level. Nothing is
// invalidated by moving control points: only the topology is baked in.
#include <array>
#include <memory>
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {

class ControlMesh;
class Topology;

enum class ElementType { Normal = 0, Special = 1 };

struct ElementPoint {
  int element = 0;
  double u = 0;
  double v = 0;
};

struct SurfacePoint {
  int face = 0;  // parametric face of the control mesh
  double u = 0;
  double v = 0;
};

// Position, derivatives and unit normal at one point (mm, and mm per unit of
// parameter). The normal is zero only where s_u x s_v vanishes.
struct LimitSample {
  Vector3 position, du, dv, duu, duv, dvv, normal;
};
// The sample whose rows s, s_u, s_v, s_uu, s_uv, s_vv are given (6 x 3), with its normal.
LimitSample limitSampleOf(const Eigen::Matrix<double, 6, 3>& rows);

// An element as bicubic B-spline patches (TVCG §3.1, eq. 26): the patch with
// corner grid `grid` (16 rows in the slot order of a regular patch, over the
// element's columns) covers a square of side `size` (element parameter units)
// of the element. Its own parameters (a, b) map to the element's by a scaling
// 1/size and a quarter turn: with `swapped`, a runs along the element's v.
// The control points are the rows of `grid` each plus `offset`, so
// s = B(a, b) * (grid + 1 offset) * p on the piece. For a special element grid
// holds displacements from the extraordinary vertex's limit point (rows sum to
// 0) and offset its limit mask: derivatives need only grid, which keeps their
// relative accuracy on deep, small pieces.
struct BsplinePiece {
  Eigen::Matrix<double, 16, Eigen::Dynamic> grid;
  Eigen::RowVectorXd offset;
  double size = 1;
  bool swapped = false;
};
// The uniform bicubic B-spline basis on a piece: rows s, s_a, s_b, s_aa, s_ab,
// s_bb; columns the 16 grid slots (slot i + 4 j: index i along a, j along b).
Eigen::Matrix<double, 6, 16> bicubicBsplineWeights(double a, double b);

struct ElementPieces {
  std::vector<int> columns;  // control vertices the element depends on
  std::vector<BsplinePiece> pieces;
};

// Special elements whose neighbourhoods have one structure (after isolation,
// every special element of one valence in regular surroundings) have the same
// pieces over their neighbourhood's vertices; only the blends of control
// vertices those vertices are differ. Whatever is linear in the pieces (the
// physical matrices' integrals) is then computed once per structure and
// mapped.
struct SharedPieces {
  int key = -1;                           // equal keys, equal `pieces`
  const ElementPieces* pieces = nullptr;  // over the neighbourhood's vertices (columns 0..n-1); owned by the surface
  Eigen::MatrixXd map;                    // neighbourhood vertices by the element's columns
};

// Rows: points; columns: control vertices; s = J * p for each coordinate.
// Rows of J sum to 1, rows of the derivative operators to 0. All the
// operators built together share one sparsity pattern (a weight that is zero
// in one and not in another is stored as an explicit zero).
struct LimitOperators {
  SparseMatrix J, Ju, Jv, Juu, Juv, Jvv;
};

class LimitSurface {
 public:
  // Throws dynsub::Error if the mesh's topology is unusable (it cannot be for
  // a ControlMesh, which is checked on construction).
  explicit LimitSurface(const ControlMesh& mesh, const SparseMatrix& freeBasis = SparseMatrix());
  ~LimitSurface();
  LimitSurface(LimitSurface&&) noexcept;
  LimitSurface& operator=(LimitSurface&&) noexcept;

  int controlVertexCount() const;
  // elementCount() of `mesh`'s limit surface, from its isolation alone
  // (without the elements' tables).
  static int elementCountOf(const ControlMesh& mesh);
  // Global refinements done before the elements: those that refine
  // semi-sharp creases away, then 0, 1 or 2 to isolate extraordinary vertices.
  int isolationLevels() const;
  // The base mesh (the elements are its faces; cut along sharp creases) and
  // its vertices as a linear blend of the control vertices (#base vertices by
  // #control vertices).
  const Topology& baseTopology() const;
  const SparseMatrix& isolationMatrix() const;

  int elementCount() const;
  ElementType elementType(int element) const;
  // The control-mesh face the element lies in.
  int elementControlFace(int element) const;
  int parametricFaceCount() const;
  // The element and element parameters of a point given on a parametric face.
  // Throws dynsub::Error if the face or the parameters are out of range.
  ElementPoint toElementPoint(const SurfacePoint& point) const;
  // The inverse: where an element point lies on the control mesh's parametric faces.
  SurfacePoint toSurfacePoint(const ElementPoint& point) const;

  LimitSample evaluate(const ElementPoint& point, const MatrixX3& controlPoints) const;
  LimitSample evaluate(const SurfacePoint& point, const MatrixX3& controlPoints) const;
  // Derivatives up to `order` (0, 1 or 2); the operators of higher ones are
  // left empty (0 x 0).
  LimitOperators operators(const std::vector<ElementPoint>& points, int order = 2) const;
  LimitOperators operators(const std::vector<SurfacePoint>& points, int order = 2) const;
  // J alone (positions), for callers that need no derivatives.
  SparseMatrix limitOperator(const std::vector<ElementPoint>& points) const;
  // The 16 B-spline control points of every normal element's patch as one
  // operator (16 #elements by #control vertices; row 16 e + slot, slots as
  // in bicubicBsplineWeights; the rows of special elements are empty): with
  // G = patchOperator() * p, any point of a normal element e is
  // bicubicBsplineWeights(u, v) * G.middleRows(16 e, 16), and forces on its
  // grid points go back to the control vertices by patchOperator()^T. Built
  // once per control-mesh topology by callers that evaluate many points of
  // one state (closest-point searches, springs).
  SparseMatrix patchOperator() const;

  // The control vertices an element depends on (sorted), and the weights of s
  // and its derivatives at one of its points over them: rows s, s_u, s_v,
  // s_uu, s_uv, s_vv (6 by elementColumns(point.element).size()). One row of
  // operators() without building a sparse matrix, for loops that visit points
  // one at a time (closest points, per-point stiffness).
  const std::vector<int>& elementColumns(int element) const;
  Eigen::Matrix<double, 6, Eigen::Dynamic> stencil(const ElementPoint& point) const;
  // Row s of stencil() alone, at about a sixth of its cost (springs and their
  // stiffness need the position's weights only).
  Eigen::RowVectorXd positionStencil(const ElementPoint& point) const;

  // A normal element is one piece of size 1. A special element is the three
  // regular pieces of each local-subdivision level 1..levels (size 2^-level);
  // the square of side 2^-levels at the extraordinary corner is left out
  // (levels in 1..60; levels > 24 are computed on demand).
  ElementPieces elementPieces(int element, int levels) const;
  // A special element's pieces as those of its neighbourhood's structure
  // (SharedPieces): elementPieces(element, levels) is, piece by piece, the
  // shared grid and offset times `map`, to rounding.
  SharedPieces sharedPieces(int element, int levels) const;

  // Row i gives the limit position of the mesh's vertex i (#mesh vertices by
  // #control vertices).
  SparseMatrix controlVertexLimitOperator() const;

 private:
  struct Impl;
  friend class SurfaceState;
  std::unique_ptr<Impl> impl_;
};

// The limit surface at one state of its control points, for many evaluations
// at that state (the Newton iterations of closest-point searches, a
// tessellation). LimitSurface::evaluate multiplies an element's (or
// subpatch's) 16 by m grid by the m control points at every call; here the
// normal elements' grid points are computed for all at reset() (grids()),
// and each special subpatch's the first time a point needs them, kept until
// the next reset(). So a point costs one bicubic evaluation, down to 12
// levels from an extraordinary vertex (deeper points take
// LimitSurface::evaluate). Equal to it to rounding. evaluate() may be called
// from several threads at once, reset() not.
class SurfaceState {
 public:
  explicit SurfaceState(const LimitSurface& surface);  // the surface must outlive this
  ~SurfaceState();
  void reset(const MatrixX3& controlPoints);
  LimitSample evaluate(const ElementPoint& point) const;
  // The surface's patchOperator(), built the first time it is asked for
  // (thread-safe), and patchOperator() times the control points of the last
  // reset(): rows 16 e .. 16 e + 15 are normal element e's grid points.
  const SparseMatrix& patchOperator() const;
  const MatrixX3& grids() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynsub
