#include "dynsub/LimitSurface.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <complex>
#include <cmath>
#include <functional>
#include <map>
#include <mutex>

#include <Eigen/Eigenvalues>

#include "PatchRules.h"
#include "dynsub/ApplyOperator.h"
#include "dynsub/CatmullClark.h"
#include "dynsub/ControlMesh.h"
#include "dynsub/Error.h"
#include "dynsub/MeshCheck.h"

namespace dynsub {

using detail::LevelPatches;
using detail::LocalMesh;
using detail::SmallStencil;

namespace {

// Neighbourhood structures keep up to this many levels of subpatches, each
// tabulated the first time a point needs it (points closer than 2^-24 to the
// extraordinary corner are computed on demand without being kept).
constexpr int kTabulatedLevels = 24;
// The cross-boundary tangent at a boundary extraordinary vertex has the
// magnitude it has at this level (see setBoundaryTangents).
constexpr int kCrossTangentLevel = 48;

// Displacements from the limit point have rows summing to exactly 0; removing
// the rounding residual at each level keeps it from being amplified 2^level-fold
// in derivatives.
void zeroRowSums(Eigen::MatrixXd& displacements) {
  const Eigen::VectorXd mean = displacements.rowwise().sum() / static_cast<double>(displacements.cols());
  displacements.colwise() -= mean;
}

// The steps of local subdivision met so far, by local topology and face:
// equal neighbourhoods share one (see extractNeighbourhood), so a surface
// builds a handful, not a few per special element. Thread-safe; a step, once
// made, stays where it is.
class StepCache {
 public:
  const detail::CornerStep& stepFor(const LocalMesh& mesh) {
    const std::lock_guard<std::mutex> lock(mutex_);
    // A topology the cache made (a step's result) is found by its address;
    // any other (a level-0 neighbourhood) by its faces, once.
    const auto known = byAddress_.find({mesh.topology.get(), mesh.face});
    if (known != byAddress_.end()) return *known->second;
    auto key = std::make_pair(mesh.topology->faces(), mesh.face);
    auto it = byStructure_.find(key);
    if (it == byStructure_.end()) {
      auto step = std::make_unique<detail::CornerStep>(detail::cornerStep(mesh.topology, mesh.face));
      byAddress_.emplace(std::make_pair(step->from.get(), step->face), step.get());
      // A step whose result has its own topology (every level past the first
      // one or two) leads to itself, found by address from then on.
      if (step->toFace == step->face && step->to->faces() == step->from->faces()) step->to = step->from;
      it = byStructure_.emplace(std::move(key), std::move(step)).first;
    }
    return *it->second;
  }

 private:
  std::mutex mutex_;
  std::map<std::pair<std::vector<Polygon>, int>, std::unique_ptr<detail::CornerStep>> byStructure_;
  std::map<std::pair<const Topology*, int>, const detail::CornerStep*> byAddress_;
};

// One level deeper around the extraordinary vertex, keeping row sums at 0.
LevelPatches subdivideDisplacements(LocalMesh& mesh, StepCache& steps) {
  LevelPatches patches = detail::subdivideAroundCorner(mesh, steps.stepFor(mesh));
  zeroRowSums(mesh.weights);
  return patches;
}

using GridMatrix = Eigen::Matrix<double, 16, Eigen::Dynamic>;
using SampleWeights = Eigen::Matrix<double, 6, Eigen::Dynamic>;  // s, su, sv, suu, suv, svv

bool needsIsolation(const Topology& topology) {
  for (int f = 0; f < topology.faceCount(); ++f) {
    if (topology.faceSize(f) != 4) return true;
    int irregular = 0;
    for (int v : topology.face(f)) irregular += !topology.isRegularVertex(v);
    if (irregular > 1) return true;
  }
  return false;
}

// Semi-sharp creases are refined away before anything else: after ceil(s)
// steps an edge of sharpness s is smooth, and what is left is smooth or
// sharp. The topology's creases are checked here (checkCreases) for meshes
// that were not read from a file.
int semiSharpLevels(const Topology& topology) {
  checkCreases(topology, "control mesh");
  double largest = 0.0;
  for (int e = 0; e < topology.edgeCount(); ++e) {
    const double sharpness = topology.edgeSharpness(e);
    if (sharpness < kInfiniteSharpness) largest = std::max(largest, sharpness);
  }
  return static_cast<int>(std::ceil(largest));
}

// The mesh cut along its infinitely sharp creases: each vertex on them
// becomes one vertex per sector (Topology::sharpSectors), so the creases are
// boundaries, and `duplication` (if not null) maps the original vertices to
// the cut mesh's. The boundary rules on the cut mesh are the crease rules on
// the original where checkCreases (MeshCheck.h) accepts the creases, as it
// did before the semi-sharp steps, which keep what it checks: a crease vertex
// keeps two or more faces on each side (the boundary vertex rule), a corner
// one face between two sharp edges (a corner). Faces keep their numbers.
Topology cutAlongCreases(const Topology& topology, SparseMatrix* duplication) {
  std::vector<Polygon> faces = topology.faces();
  std::vector<int> source(topology.vertexCount());
  for (int v = 0; v < topology.vertexCount(); ++v) source[v] = v;
  for (int v = 0; v < topology.vertexCount(); ++v) {
    const std::vector<std::vector<int>> sectors = topology.sharpSectors(v);
    for (size_t k = 1; k < sectors.size(); ++k) {
      const int copy = static_cast<int>(source.size());
      source.push_back(v);
      for (int f : sectors[k]) faces[f][topology.corner(f, v)] = copy;
    }
  }
  if (duplication) {
    std::vector<Triplet> ones;
    for (size_t i = 0; i < source.size(); ++i) ones.emplace_back(static_cast<int>(i), source[i], 1.0);
    duplication->resize(static_cast<Eigen::Index>(source.size()), topology.vertexCount());
    duplication->setFromTriplets(ones.begin(), ones.end());
  }
  return Topology(static_cast<int>(source.size()), std::move(faces));
}

// The global refinements before the elements (LimitSurface.h): semi-sharp
// creases refined away, the cut along sharp creases, then the steps that
// isolate extraordinary vertices. `refined` sees each step (the topology it
// refined and its refinement, whose topology it must leave), `cut` the
// cut's duplication matrix; either may be empty (then no matrix is built for
// it). Returns the base topology.
Topology refineToBase(Topology base, const std::function<void(const Topology&, Refinement&)>& refined,
                      const std::function<void(const SparseMatrix&)>& cut) {
  const auto step = [&] {
    Refinement refinement = refine(base);
    if (refined) refined(base, refinement);
    base = std::move(refinement.topology);
  };
  const int creaseLevels = semiSharpLevels(base);
  for (int level = 0; level < creaseLevels; ++level) step();
  if (base.hasCreases()) {
    SparseMatrix duplication;
    base = cutAlongCreases(base, cut ? &duplication : nullptr);
    if (cut) cut(duplication);
  }
  // One step isolates every extraordinary vertex of an all-quad mesh; a second
  // one those at the centres of former n-gons.
  for (int levels = 0; needsIsolation(base); ++levels) {
    if (levels == 2) throw Error("internal: extraordinary vertices are not isolated after two steps");
    step();
  }
  return base;
}

// Rewrites derivative rows taken in parameters (a, b) into parameters (u, v),
// given T = d(a, b)/d(u, v): gradient T^T g, Hessian T^T H T. Column by
// column, so that nothing is allocated (this runs once per evaluated point).
// With rows = 3 only s, s_u, s_v are rewritten (the rest may hold anything).
template <class Rows>
void applyChainRule(Rows& w, const Eigen::Matrix2d& t, int rows = 6) {
  // Row 0, the position, does not depend on the parametrization.
  if (rows <= 1 || t.isIdentity(0.0)) return;
  if (rows <= 3) {
    for (Eigen::Index c = 0; c < w.cols(); ++c) {
      const double da = w(1, c), db = w(2, c);
      w(1, c) = t(0, 0) * da + t(1, 0) * db;
      w(2, c) = t(0, 1) * da + t(1, 1) * db;
    }
    return;
  }
  const double uu0 = t(0, 0) * t(0, 0), uu1 = 2.0 * t(0, 0) * t(1, 0), uu2 = t(1, 0) * t(1, 0);
  const double uv0 = t(0, 0) * t(0, 1), uv1 = t(0, 0) * t(1, 1) + t(1, 0) * t(0, 1), uv2 = t(1, 0) * t(1, 1);
  const double vv0 = t(0, 1) * t(0, 1), vv1 = 2.0 * t(0, 1) * t(1, 1), vv2 = t(1, 1) * t(1, 1);
  for (Eigen::Index c = 0; c < w.cols(); ++c) {
    const double da = w(1, c), db = w(2, c), daa = w(3, c), dab = w(4, c), dbb = w(5, c);
    w(1, c) = t(0, 0) * da + t(1, 0) * db;
    w(2, c) = t(0, 1) * da + t(1, 1) * db;
    w(3, c) = uu0 * daa + uu1 * dab + uu2 * dbb;
    w(4, c) = uv0 * daa + uv1 * dab + uv2 * dbb;
    w(5, c) = vv0 * daa + vv1 * dab + vv2 * dbb;
  }
}

// Quadrant of (u, v) in a quad: the child of CatmullClark.h's numbering.
int quadrant(double u, double v) {
  if (u < 0.5) return v < 0.5 ? 0 : 3;
  return v < 0.5 ? 1 : 2;
}

// The control-vertex columns that sets of base vertices blend (rows of the
// isolation matrix), sorted; one per construction, which builds its elements
// one at a time. Each column is taken once, as first met (mark_ holds the
// call that last met it), so that only the distinct ones are sorted: after
// two isolating steps a base vertex blends a dozen or more control vertices,
// and an element's base vertices share most of them.
class ColumnGatherer {
 public:
  explicit ColumnGatherer(const SparseMatrix& isolation) : isolation_(isolation), mark_(isolation.cols(), -1) {}
  std::vector<int> operator()(const std::vector<int>& baseVertices) {
    ++call_;
    std::vector<int> columns;
    for (int b : baseVertices) {
      for (SparseMatrix::InnerIterator it(isolation_, b); it; ++it) {
        const int c = static_cast<int>(it.col());
        if (mark_[c] == call_) continue;
        mark_[c] = call_;
        columns.push_back(c);
      }
    }
    std::sort(columns.begin(), columns.end());
    return columns;
  }

 private:
  const SparseMatrix& isolation_;
  std::vector<int> mark_;
  int call_ = 0;
};

}  // namespace

struct LimitSurface::Impl {
  struct Element {
    ElementType type = ElementType::Normal;
    int controlFace = -1;
    int corner = -1;   // special: corner of the extraordinary vertex
    int special = -1;  // index into specials
    std::vector<int> columns;
    GridMatrix grid;  // normal: 16 B-spline control points over `columns`
    // Normal, when each grid point is a control vertex itself (no ghost, no
    // isolation): the column of each slot, so that a point's weights are the
    // B-spline basis itself; else slotColumn[0] = -1.
    std::array<int, 16> slotColumn{-1};
    // Special: the structure of its neighbourhood (index into `structures`),
    // and the base vertex each neighbourhood vertex is. The structure map
    // (neighbourhood vertices by columns) is their rows of `isolation`:
    // mapColumns holds where each of those rows' weights falls in `columns`,
    // row after row. Kept as indices into `isolation` rather than as a dense
    // map: a scan's triangle mesh has a special element on every face.
    int structure = -1;
    std::vector<int> mapVertices;
    std::vector<int> mapColumns;
  };
  // A special element's masks at its extraordinary vertex over its columns;
  // a structure's (below) also its subpatches, level by level.
  // Levels are tabulated when a point first needs them, and points are
  // evaluated from several threads at once (closest-point searches), so the
  // table grows under `mutex`. levels[n - 1] is written once, before
  // `tabulated` reaches n, and never moved (the vector is sized up front):
  // a reader that sees tabulated >= n may use it without the lock.
  struct Special {
    std::vector<int> columns;
    Eigen::Matrix<double, 3, Eigen::Dynamic> vertexMasks;  // limit position, tangent u, tangent v
    std::vector<LevelPatches> levels;  // levels[n - 1]: subpatches at level n
    std::atomic<int> tabulated{0};
    std::mutex mutex;
    LocalMesh deepest;  // the neighbourhood after `tabulated` levels
    // levels and deepest hold displacements from the limit position (row 0 of vertexMasks).
  };

  int controlVertexCount = 0;  // the free points' with a free basis
  int meshVertexCount = 0;
  int isolationLevels = 0;
  Topology base;
  SparseMatrix isolation;                         // base vertices <- control vertices
  std::vector<std::vector<int>> childFaceOffset;  // per isolation level
  // Per isolation level, for each child face: its parent face and child index.
  std::vector<std::vector<std::pair<int, int>>> parentOf;
  std::vector<int> parametricFaceOffset;          // per control face, plus the total
  std::vector<int> controlFaceSize;
  std::vector<Element> elements;
  std::vector<std::unique_ptr<Special>> specials;
  // One special per neighbourhood structure, over the neighbourhood's own
  // vertices (identity weights): what every special element of that
  // structure is, up to its structure map. Few: after isolation a structure
  // is a valence (and whether at a boundary).
  std::map<std::vector<int>, int> structureIndex;
  std::vector<std::unique_ptr<Special>> structures;
  std::vector<std::shared_ptr<const Topology>> structureTopologies;  // each structure's, before subdivision
  // Their pieces, per (structure, corner, levels), made on first use.
  mutable std::map<std::array<int, 3>, ElementPieces> structurePieces;
  mutable std::mutex structurePiecesMutex;
  mutable StepCache steps;

  // The subpatches of a special element at a level 1..kTabulatedLevels,
  // tabulated on first use.
  const LevelPatches& level(Special& special, int n) const {
    if (special.tabulated.load(std::memory_order_acquire) < n) {
      const std::lock_guard<std::mutex> lock(special.mutex);
      for (int next = special.tabulated.load(std::memory_order_relaxed) + 1; next <= n; ++next) {
        special.levels[next - 1] = subdivideDisplacements(special.deepest, steps);
        special.tabulated.store(next, std::memory_order_release);
      }
    }
    return special.levels[n - 1];
  }
  // The neighbourhood after kTabulatedLevels levels, from which deeper ones
  // are computed; final once every level is tabulated.
  const LocalMesh& deepestTabulated(Special& special) const {
    level(special, kTabulatedLevels);
    return special.deepest;
  }

  // Calls visit(k, c, w) for each weight of a special element's structure
  // map: its neighbourhood vertex k is, in part, w times its column c. Row by
  // row, each row's columns in increasing order.
  template <class Visit>
  void forEachMapWeight(const Element& element, Visit&& visit) const {
    const int* column = element.mapColumns.data();
    for (size_t k = 0; k < element.mapVertices.size(); ++k)
      for (SparseMatrix::InnerIterator it(isolation, element.mapVertices[k]); it; ++it)
        visit(static_cast<Eigen::Index>(k), *column++, it.value());
  }
  Eigen::MatrixXd structureMap(const Element& element) const {
    Eigen::MatrixXd map = Eigen::MatrixXd::Zero(element.mapVertices.size(), element.columns.size());
    forEachMapWeight(element, [&](Eigen::Index k, int c, double w) { map(k, c) = w; });
    return map;
  }
  // The positions of a special element's neighbourhood vertices (the
  // structure map applied to the control points), into out.
  template <class Out>
  void neighbourhoodPoints(const Element& element, const MatrixX3& controlPoints, Out& out) const {
    out.setZero(element.mapVertices.size(), 3);
    forEachMapWeight(element,
                     [&](Eigen::Index k, int c, double w) { out.row(k) += w * controlPoints.row(element.columns[c]); });
  }
  // Adds `weight` times a base vertex's blend of control vertices to `row`,
  // a row over `columns` (which hold the blend's columns).
  template <class Row>
  void addRowOver(const std::vector<int>& columns, int baseVertex, double weight, Row&& row) const {
    for (SparseMatrix::InnerIterator it(isolation, baseVertex); it; ++it) {
      const auto position = std::lower_bound(columns.begin(), columns.end(), static_cast<int>(it.col()));
      row(position - columns.begin()) += weight * it.value();
    }
  }

  void buildNormal(Element& element, int face, ColumnGatherer& gatherColumns) {
    std::array<SmallStencil, 16> grid;
    if (!detail::gatherRegularPatch(base, face, grid)) throw Error("internal: normal element is not regular");
    std::vector<int> baseVertices;
    for (const SmallStencil& s : grid) {
      for (const auto& [v, w] : s) baseVertices.push_back(v);
    }
    element.columns = gatherColumns(baseVertices);
    element.grid.setZero(16, element.columns.size());
    for (int s = 0; s < 16; ++s) {
      for (const auto& [v, w] : grid[s]) addRowOver(element.columns, v, w, element.grid.row(s));
    }
    if (element.columns.size() != 16) return;
    for (int s = 0; s < 16; ++s) {
      Eigen::Index column = 0;
      const double largest = element.grid.row(s).maxCoeff(&column);
      if (largest != 1.0 || element.grid.row(s).cwiseAbs().sum() != 1.0) {
        element.slotColumn[0] = -1;
        return;
      }
      element.slotColumn[s] = static_cast<int>(column);
    }
  }

  // A special element's tables from its neighbourhood `local`, whose
  // vertices are the blends (rows of local.weights) of `columns`.
  // With `tabulate` (a structure), its levels are kept as they are needed.
  std::unique_ptr<Special> makeSpecial(LocalMesh local, std::vector<int> columns, bool tabulate) {
    auto owned = std::make_unique<Special>();
    Special& special = *owned;
    special.columns = std::move(columns);
    const int localX = local.topology->face(local.face)[0];
    const detail::VertexMasks masks = detail::vertexMasks(*local.topology, localX, local.face);
    special.vertexMasks.setZero(3, special.columns.size());
    const SmallStencil* rows[3] = {&masks.position, &masks.tangentU, &masks.tangentV};
    for (int r = 0; r < 3; ++r) {
      for (const auto& [v, w] : *rows[r]) special.vertexMasks.row(r) += w * local.weights.row(v);
    }
    // The neighbourhood is carried as displacements from the limit point
    // (every row minus the limit mask). Subdivision maps displacements to
    // displacements (rows of A sum to 1, and the limit point is invariant), and
    // they shrink like lambda^level, so their relative accuracy survives any
    // depth; carried as plain weights, rounding of 1e-16 would be amplified
    // 2^level-fold in the derivatives.
    // `along` is a mask over the level-0 local vertices: map it before they
    // become displacements.
    Eigen::RowVectorXd along = Eigen::RowVectorXd::Zero(special.columns.size());
    for (const auto& [v, w] : masks.along) along += w * local.weights.row(v);
    local.weights.rowwise() -= special.vertexMasks.row(0);
    zeroRowSums(local.weights);
    if (masks.boundary) setBoundaryTangents(special, local, masks, along);
    if (tabulate) {
      special.levels.resize(kTabulatedLevels);
      special.deepest = std::move(local);
    }
    return owned;
  }

  void buildSpecial(Element& element, int face, ColumnGatherer& gatherColumns) {
    const int x = base.face(face)[element.corner];
    detail::Neighbourhood neighbourhood = detail::extractNeighbourhood(base, x, face);
    const std::vector<int> columns = gatherColumns(neighbourhood.parentVertex);
    const int localFace = neighbourhood.face;

    // The structure: neighbourhoods are numbered by their structure
    // (extractNeighbourhood), so equal ones have equal polygons, and share
    // one Topology (a mesh of triangles has a special element on every
    // face, each of whose topologies would otherwise be built and kept).
    std::vector<int> key{localFace};
    for (const Polygon& polygon : neighbourhood.faces) {
      key.push_back(-static_cast<int>(polygon.size()));
      key.insert(key.end(), polygon.begin(), polygon.end());
    }
    const auto [found, added] = structureIndex.try_emplace(std::move(key), static_cast<int>(structures.size()));
    if (added) {
      const int n = static_cast<int>(neighbourhood.parentVertex.size());
      structureTopologies.push_back(std::make_shared<const Topology>(n, std::move(neighbourhood.faces)));
      std::vector<int> vertices(n);
      for (int i = 0; i < n; ++i) vertices[i] = i;
      structures.push_back(
          makeSpecial(LocalMesh{structureTopologies.back(), Eigen::MatrixXd::Identity(n, n), localFace},
                      std::move(vertices), true));
    }
    element.structure = found->second;
    element.mapVertices = std::move(neighbourhood.parentVertex);
    size_t entries = 0;
    for (const int b : element.mapVertices) entries += static_cast<size_t>(isolation.row(b).nonZeros());
    element.mapColumns.reserve(entries);
    for (const int b : element.mapVertices)
      for (SparseMatrix::InnerIterator it(isolation, b); it; ++it)
        element.mapColumns.push_back(static_cast<int>(
            std::lower_bound(columns.begin(), columns.end(), static_cast<int>(it.col())) - columns.begin()));
    element.columns = columns;
    element.special = static_cast<int>(specials.size());
    // The element keeps only its masks. Its subpatches are its
    // structure's times its structure map: subdivision is linear, and a structure's
    // displacements from its limit point, times the blends, are the element's
    // (the blends' rows sum to 1). Tabulated per element they would take
    // memory, and time to fault it in, for every special element rather than
    // for the few structures.
    if (!base.isBoundaryVertex(x)) {
      // At an interior vertex the masks are linear in the blends too: the
      // structure's masks times the structure map.
      auto owned = std::make_unique<Special>();
      owned->columns = columns;
      owned->vertexMasks.setZero(3, static_cast<Eigen::Index>(columns.size()));
      const Eigen::Matrix<double, 3, Eigen::Dynamic>& masks = structures[element.structure]->vertexMasks;
      forEachMapWeight(element,
                       [&](Eigen::Index k, int c, double w) { owned->vertexMasks.col(c) += w * masks.col(k); });
      specials.push_back(std::move(owned));
      return;
    }
    // At a boundary vertex the cross-boundary tangent keeps the eigen-terms
    // that are large in these blends (setBoundaryTangents), a choice that is
    // not linear in them: so it is found from the element's own weights.
    LocalMesh local;
    local.topology = structureTopologies[element.structure];
    local.face = localFace;
    local.weights.setZero(static_cast<Eigen::Index>(element.mapVertices.size()),
                          static_cast<Eigen::Index>(columns.size()));
    forEachMapWeight(element, [&](Eigen::Index k, int c, double w) { local.weights(k, c) += w; });
    specials.push_back(makeSpecial(std::move(local), columns, false));
  }

  // The pieces of a special element's levels 1..levels (three subpatches
  // each) from `special`'s tables, over its columns.
  ElementPieces piecesOf(Special& special, int corner, int levels) const {
    ElementPieces result;
    result.columns = special.columns;
    const Eigen::Matrix2d toCorner = detail::cornerFrameJacobian(corner);
    LocalMesh local;
    if (levels > kTabulatedLevels) local = deepestTabulated(special);
    LevelPatches deeper;
    for (int level = 1; level <= levels; ++level) {
      if (level > kTabulatedLevels) deeper = subdivideDisplacements(local, steps);
      const LevelPatches& patches = level <= kTabulatedLevels ? this->level(special, level) : deeper;
      for (int child = 1; child <= 3; ++child) {
        BsplinePiece piece;
        piece.grid = patches[child - 1];
        piece.offset = special.vertexMasks.row(0);
        piece.size = std::ldexp(1.0, -level);
        // d(piece a, b)/d(element u, v) is a signed permutation: a follows u unless it is swapped.
        const Eigen::Matrix2d turn = detail::cornerFrameJacobian(child) * toCorner;
        piece.swapped = turn(0, 0) == 0.0;
        result.pieces.push_back(std::move(piece));
      }
    }
    return result;
  }

  // Tangents at a boundary extraordinary vertex. Along the boundary the
  // boundary curve's tangent is exact. Across it no closed-form mask fits the
  // standard boundary rules (the Biermann et al. mask, made for modified rules,
  // is off by up to 2e-2 rad here), so the cross tangent comes from the
  // subdivision's own eigenstructure. Past the first level or two one step S
  // maps the neighbourhood's displacements to the next level's, so at level
  // L >= m they are S^(L-m) W_m = sum_j lambda_j^(L-m) r_j (l_j W_m) over the
  // eigenvalues lambda_j, right eigenvectors r_j and left ones l_j of S. The
  // displacement of an interior neighbour of the vertex, scaled by 2^L, turns
  // across the boundary at the rate of the largest eigenvalue it holds; read
  // at a finite level L the next eigenvalues still pull it off by
  // (lambda_next / lambda_top)^L, which at L = 48 is 2e-2 rad at 12 faces and
  // 1.5 rad at 50, where the eigenvalues crowd together. Here only the top
  // eigenvalue's terms are kept: the limit direction, exact to the
  // eigensolver's accuracy, with the magnitude of a reading at
  // kCrossTangentLevel, so that the masks equal such a reading wherever it
  // converges. Still a fixed linear mask, so J_u and J_v stay linear operators.
  void setBoundaryTangents(Special& special, const LocalMesh& level0, const detail::VertexMasks& masks,
                           const Eigen::RowVectorXd& along) {
    LocalMesh deep = level0;
    int level = 0;
    for (;; ++level) {
      const detail::CornerStep& step = steps.stepFor(deep);
      if (step.to == step.from && step.toFace == step.face) break;
      if (level == 8) throw Error("internal: the subdivision around a boundary vertex does not repeat");
      subdivideDisplacements(deep, steps);
    }
    const Eigen::MatrixXd& repeated = steps.stepFor(deep).next;
    const Topology& topology = *deep.topology;
    const Polygon& face = topology.face(deep.face);
    const int x = face[0];
    // The new 1-ring of x (x, and the corners of the faces at x) is made
    // from the old 1-ring alone, so S is block triangular: the eigenvalues
    // that matter, and their left eigenvectors (zero off the 1-ring), are
    // those of S restricted to the 1-ring, a quarter of the work of the whole
    // neighbourhood's at a fan of 50 faces, times the fan's 50 elements.
    std::vector<int> ring;
    for (int f : topology.vertexFaces(x)) ring.insert(ring.end(), topology.face(f).begin(), topology.face(f).end());
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    const Eigen::MatrixXd ringStep = repeated(ring, ring);
    if (std::abs(repeated(ring, Eigen::all).cwiseAbs().sum() - ringStep.cwiseAbs().sum()) > 1e-12 * ringStep.cwiseAbs().sum()) {
      throw Error("internal: the 1-ring of a boundary vertex is not closed under subdivision");
    }
    const int interiorVertex = !topology.isBoundaryEdge(topology.findEdge(x, face[1])) ? face[1] : face[3];
    const Eigen::Index interior = std::lower_bound(ring.begin(), ring.end(), interiorVertex) - ring.begin();
    const Eigen::EigenSolver<Eigen::MatrixXd> solver(ringStep);
    if (solver.info() != Eigen::Success) throw Error("internal: no eigenvectors for a boundary vertex's subdivision");
    const Eigen::VectorXcd lambda = solver.eigenvalues();
    const Eigen::MatrixXcd right = solver.eigenvectors();
    const Eigen::MatrixXcd left = right.inverse();
    const Eigen::MatrixXcd coefficients = left * deep.weights(ring, Eigen::all).cast<std::complex<double>>();  // l_j W_m
    // The terms of the interior neighbour's displacement, and the largest
    // eigenvalue among them (not 1: displacements from the limit point hold
    // none of it, but for rounding).
    std::vector<double> size(lambda.size(), 0.0);
    double top = 0.0, largestTerm = 0.0;
    for (Eigen::Index j = 0; j < lambda.size(); ++j) {
      size[j] = std::abs(right(interior, j)) * coefficients.row(j).norm();
      if (std::abs(lambda(j) - 1.0) > 1e-6) largestTerm = std::max(largestTerm, size[j]);
    }
    auto held = [&](Eigen::Index j) { return std::abs(lambda(j) - 1.0) > 1e-6 && size[j] > 1e-9 * largestTerm; };
    for (Eigen::Index j = 0; j < lambda.size(); ++j) {
      if (held(j)) top = std::max(top, std::abs(lambda(j)));
    }
    Eigen::RowVectorXcd sum = Eigen::RowVectorXcd::Zero(deep.weights.cols());
    for (Eigen::Index j = 0; j < lambda.size(); ++j) {
      if (held(j) && std::abs(lambda(j)) >= top * (1.0 - 1e-9)) {
        sum += std::pow(lambda(j), kCrossTangentLevel - level) * right(interior, j) * coefficients.row(j);
      }
    }
    const Eigen::RowVectorXd across = std::ldexp(1.0, kCrossTangentLevel) * sum.real();
    const double theta = M_PI / masks.faces;
    special.vertexMasks.row(1) = std::cos(masks.fanPosition * theta) * along +
                                 std::sin(masks.fanPosition * theta) * across;
    special.vertexMasks.row(2) = std::cos((masks.fanPosition + 1) * theta) * along +
                                 std::sin((masks.fanPosition + 1) * theta) * across;
  }

  void checkPoint(const ElementPoint& point) const {
    if (point.element < 0 || point.element >= static_cast<int>(elements.size())) {
      throw Error("element " + std::to_string(point.element) + " does not exist (the surface has " +
                  std::to_string(elements.size()) + " elements)");
    }
    if (!(point.u >= 0.0 && point.u <= 1.0 && point.v >= 0.0 && point.v <= 1.0)) {
      throw Error("parameters (" + std::to_string(point.u) + ", " + std::to_string(point.v) +
                  ") of element " + std::to_string(point.element) + " are outside [0,1]^2");
    }
  }

  // Where a point of a special element lies: the regular subpatch (grid rows
  // of displacements over its structure's neighbourhood vertices; times the
  // element's structure map, over its columns), its own parameters and
  // d(patch parameters)/d(element u, v); no patch at the extraordinary corner.
  struct SubpatchPoint {
    const GridMatrix* patch = nullptr;  // null: the point is the extraordinary vertex
    LevelPatches deeper;                // storage for levels past the tabulated ones
    int level = 0, child = 0;           // of the patch: level 1.., child 1..3
    double u = 0, v = 0;
    Eigen::Matrix2d jacobian;
  };
  // fetch = false: level, child, parameters and jacobian only (patch stays null).
  SubpatchPoint locateSubpatch(const Element& element, const ElementPoint& point, bool fetch = true) const {
    Special& structure = *structures[element.structure];
    SubpatchPoint result;
    // Parameters with the extraordinary vertex at the origin.
    const auto [a, b] = detail::cornerFrame(element.corner, point.u, point.v);
    const Eigen::Matrix2d toCorner = detail::cornerFrameJacobian(element.corner);
    if (a == 0.0 && b == 0.0) {
      result.jacobian = toCorner;
      return result;
    }
    // The level n >= 1 at which the point lies in a regular subpatch: the
    // smallest n with max(a, b) >= 2^-n.
    int exponent = 0;
    std::frexp(std::max(a, b), &exponent);
    const int level = std::max(1, 1 - exponent);
    const double x = std::ldexp(a, level - 1);  // exact scaling into [0,1]^2
    const double y = std::ldexp(b, level - 1);
    const int child = quadrant(x, y);
    const auto [childU, childV] = detail::cornerFrame(child, x, y);
    result.u = std::min(1.0, 2.0 * childU);
    result.v = std::min(1.0, 2.0 * childV);
    result.level = level;
    result.child = child;
    result.jacobian = std::ldexp(1.0, level) * detail::cornerFrameJacobian(child) * toCorner;
    if (!fetch) return result;
    if (level <= kTabulatedLevels) {
      result.patch = &Impl::level(structure, level)[child - 1];
    } else {
      LocalMesh local = deepestTabulated(structure);
      for (int n = kTabulatedLevels + 1; n <= level; ++n) result.deeper = subdivideDisplacements(local, steps);
      result.patch = &result.deeper[child - 1];
    }
    return result;
  }

  // Weights of s and its derivatives at an element point, over
  // element.columns, into w (resized only if its size differs, so that a
  // loop over points reuses one buffer). With rows = 1 or 3 only the first
  // rows (s; s, s_u, s_v) are computed, the others left as they were.
  void weightsInto(const ElementPoint& point, SampleWeights& w, int rows = 6) const {
    checkPoint(point);
    const Element& element = elements[point.element];
    // LazyProduct: these products are too small for Eigen's blocked GEMM,
    // whose packing and allocation would dominate closest-point searches.
    auto product = [&](const Eigen::Matrix<double, 6, 16>& b, const auto& grid) {
      if (rows == 6) {
        w.noalias() = b.lazyProduct(grid);
      } else if (rows == 3) {
        w.topRows<3>().noalias() = b.topRows<3>().lazyProduct(grid);
      } else {
        // Summed in the order the rows above are (k ascending), so that the
        // position's weights equal row 0 of the whole product to the bit.
        for (Eigen::Index j = 0; j < grid.cols(); ++j) {
          double sum = b(0, 0) * grid(0, j);
          for (Eigen::Index k = 1; k < 16; ++k) sum += b(0, k) * grid(k, j);
          w(0, j) = sum;
        }
      }
    };
    if (element.type == ElementType::Normal) {
      w.resize(6, element.grid.cols());
      // The common case (a normal element of a mesh that needed no
      // isolation) as a fixed-size product, which Eigen vectorizes.
      const Eigen::Matrix<double, 6, 16> basis = detail::bsplineWeights(point.u, point.v);
      if (element.slotColumn[0] >= 0) {
        for (int slot = 0; slot < 16; ++slot) w.col(element.slotColumn[slot]).head(rows) = basis.col(slot).head(rows);
      } else if (element.grid.cols() == 16) {
        product(basis, Eigen::Map<const Eigen::Matrix<double, 16, 16>>(element.grid.data()));
      } else {
        product(basis, element.grid);
      }
      return;
    }
    const Special& special = *specials[element.special];
    const SubpatchPoint at = locateSubpatch(element, point);
    w.resize(6, static_cast<Eigen::Index>(special.columns.size()));
    if (!at.patch) {
      w.setZero();
      w.topRows(3) = special.vertexMasks;
    } else {
      // Over the structure's vertices first, then their blends of the columns;
      // summed in one order whatever `rows` is (positionStencil is row 0 of
      // stencil to the bit).
      const int count = rows == 6 ? 6 : rows == 3 ? 3 : 1;
      const Eigen::Matrix<double, 6, 16> basis = detail::bsplineWeights(at.u, at.v);
      const GridMatrix& patch = *at.patch;
      const Eigen::Index m = patch.cols();
      Eigen::Matrix<double, 6, Eigen::Dynamic> local(6, m);
      for (Eigen::Index k = 0; k < m; ++k) {
        for (int r = 0; r < count; ++r) {
          double sum = basis(r, 0) * patch(0, k);
          for (int g = 1; g < 16; ++g) sum += basis(r, g) * patch(g, k);
          local(r, k) = sum;
        }
      }
      w.topRows(count).setZero();
      forEachMapWeight(element, [&](Eigen::Index k, int c, double weight) {
        for (int r = 0; r < count; ++r) w(r, c) += local(r, k) * weight;
      });
      w.row(0) += special.vertexMasks.row(0);  // the patch holds displacements from the limit point
    }
    applyChainRule(w, at.jacobian, rows);
  }
  SampleWeights weights(const ElementPoint& point) const {
    SampleWeights w;
    weightsInto(point, w);
    return w;
  }

  // s and its derivatives (rows) at an element point for given control
  // points: weights() applied, without allocating (the closest-point
  // searches' inner loop).
  // weights (rows over `columns`) applied to the control points, into out.
  template <class Weights, class Out>
  static void blend(const Weights& weights, const std::vector<int>& columns, const MatrixX3& controlPoints, Out& out) {
    out.setZero();
    for (size_t c = 0; c < columns.size(); ++c) {
      out.noalias() += weights.col(static_cast<Eigen::Index>(c)) * controlPoints.row(columns[c]);
    }
  }

  Eigen::Matrix<double, 6, 3> values(const ElementPoint& point, const MatrixX3& controlPoints) const {
    checkPoint(point);
    const Element& element = elements[point.element];
    // The 16 grid points (or displacements) of the piece the point lies on.
    Eigen::Matrix<double, 16, 3> grid;
    if (element.type == ElementType::Normal) {
      blend(element.grid, element.columns, controlPoints, grid);
      return detail::bsplineWeights(point.u, point.v) * grid;
    }
    const Special& special = *specials[element.special];
    const SubpatchPoint at = locateSubpatch(element, point);
    Eigen::Matrix<double, 6, 3> result = Eigen::Matrix<double, 6, 3>::Zero();
    Eigen::Matrix<double, 3, 3> masks;
    blend(special.vertexMasks, special.columns, controlPoints, masks);
    if (!at.patch) {
      result.topRows(3) = masks;
    } else {
      Eigen::Matrix<double, Eigen::Dynamic, 3> local;
      neighbourhoodPoints(element, controlPoints, local);
      grid.noalias() = *at.patch * local;
      result = detail::bsplineWeights(at.u, at.v) * grid;
      result.row(0) += masks.row(0);
    }
    applyChainRule(result, at.jacobian);
    return result;
  }

  // The element point of a surface point and d(element u, v)/d(surface u, v).
  ElementPoint locate(const SurfacePoint& point, Eigen::Matrix2d& jacobian) const {
    if (point.face < 0 || point.face >= parametricFaceOffset.back()) {
      throw Error("parametric face " + std::to_string(point.face) + " does not exist (the control mesh has " +
                  std::to_string(parametricFaceOffset.back()) + ")");
    }
    if (!(point.u >= 0.0 && point.u <= 1.0 && point.v >= 0.0 && point.v <= 1.0)) {
      throw Error("parameters (" + std::to_string(point.u) + ", " + std::to_string(point.v) + ") of face " +
                  std::to_string(point.face) + " are outside [0,1]^2");
    }
    const int controlFace = static_cast<int>(std::upper_bound(parametricFaceOffset.begin(),
                                                              parametricFaceOffset.end(), point.face) -
                                             parametricFaceOffset.begin()) - 1;
    jacobian.setIdentity();
    ElementPoint result{controlFace, point.u, point.v};
    for (int level = 0; level < isolationLevels; ++level) {
      int child = 0;
      if (level == 0 && controlFaceSize[controlFace] != 4) {
        child = point.face - parametricFaceOffset[controlFace];
      } else {
        child = quadrant(result.u, result.v);
        const auto [a, b] = detail::cornerFrame(child, result.u, result.v);
        result.u = std::min(1.0, 2.0 * a);
        result.v = std::min(1.0, 2.0 * b);
        jacobian = 2.0 * detail::cornerFrameJacobian(child) * jacobian;
      }
      result.element = childFaceOffset[level][result.element] + child;
    }
    return result;
  }

  const std::vector<int>& columnsOf(int element) const { return elements[element].columns; }
};

LimitSurface::LimitSurface(const ControlMesh& mesh, const SparseMatrix& freeBasis) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.controlVertexCount = mesh.vertexCount();
  s.meshVertexCount = mesh.vertexCount();
  if (freeBasis.size() > 0 && (freeBasis.rows() != mesh.vertexCount() || freeBasis.cols() == 0)) {
    throw Error("internal: a free basis of " + std::to_string(freeBasis.rows()) + " rows for " +
                std::to_string(mesh.vertexCount()) + " control vertices");
  }
  s.base = mesh.topology();
  for (int f = 0; f < s.base.faceCount(); ++f) s.controlFaceSize.push_back(s.base.faceSize(f));
  s.parametricFaceOffset.push_back(0);
  for (int size : s.controlFaceSize) s.parametricFaceOffset.push_back(s.parametricFaceOffset.back() + (size == 4 ? 1 : size));

  s.isolation.resize(s.controlVertexCount, s.controlVertexCount);
  s.isolation.setIdentity();
  std::vector<int> controlFaceOf(s.base.faceCount());
  for (int f = 0; f < s.base.faceCount(); ++f) controlFaceOf[f] = f;
  const auto refined = [&](const Topology& parent, Refinement& refinement) {
    s.isolation = refinement.subdivisionMatrix * s.isolation;
    std::vector<int> childControlFace(refinement.topology.faceCount());
    std::vector<std::pair<int, int>> parents(refinement.topology.faceCount());
    for (int f = 0; f < parent.faceCount(); ++f) {
      for (int k = 0; k < parent.faceSize(f); ++k) {
        const int child = refinement.childFaceOffset[f] + k;
        childControlFace[child] = controlFaceOf[f];
        parents[child] = {f, k};
      }
    }
    controlFaceOf = std::move(childControlFace);
    s.parentOf.push_back(std::move(parents));
    s.childFaceOffset.push_back(std::move(refinement.childFaceOffset));
    ++s.isolationLevels;
  };
  s.base = refineToBase(std::move(s.base), refined,
                        [&s](const SparseMatrix& duplication) { s.isolation = duplication * s.isolation; });
  if (freeBasis.size() > 0) {
    s.isolation = s.isolation * freeBasis;
    s.controlVertexCount = static_cast<int>(freeBasis.cols());
  }
  s.isolation.makeCompressed();

  s.elements.resize(s.base.faceCount());
  ColumnGatherer gatherColumns(s.isolation);
  for (int f = 0; f < s.base.faceCount(); ++f) {
    Impl::Element& element = s.elements[f];
    element.controlFace = controlFaceOf[f];
    for (int k = 0; k < 4; ++k) {
      if (!s.base.isRegularVertex(s.base.face(f)[k])) element.corner = k;
    }
    if (element.corner < 0) {
      s.buildNormal(element, f, gatherColumns);
    } else {
      element.type = ElementType::Special;
      s.buildSpecial(element, f, gatherColumns);
    }
  }
}

int LimitSurface::elementCountOf(const ControlMesh& mesh) {
  // The constructor's refinements, on the topology alone.
  return refineToBase(mesh.topology(), {}, {}).faceCount();
}

LimitSurface::~LimitSurface() = default;
LimitSurface::LimitSurface(LimitSurface&&) noexcept = default;
LimitSurface& LimitSurface::operator=(LimitSurface&&) noexcept = default;

int LimitSurface::controlVertexCount() const { return impl_->controlVertexCount; }
int LimitSurface::isolationLevels() const { return impl_->isolationLevels; }
const Topology& LimitSurface::baseTopology() const { return impl_->base; }
const SparseMatrix& LimitSurface::isolationMatrix() const { return impl_->isolation; }
int LimitSurface::elementCount() const { return static_cast<int>(impl_->elements.size()); }
ElementType LimitSurface::elementType(int element) const { return impl_->elements.at(element).type; }
int LimitSurface::elementControlFace(int element) const { return impl_->elements.at(element).controlFace; }
int LimitSurface::parametricFaceCount() const { return impl_->parametricFaceOffset.back(); }

ElementPoint LimitSurface::toElementPoint(const SurfacePoint& point) const {
  Eigen::Matrix2d jacobian;
  return impl_->locate(point, jacobian);
}

SurfacePoint LimitSurface::toSurfacePoint(const ElementPoint& point) const {
  const Impl& s = *impl_;
  if (point.element < 0 || point.element >= elementCount()) {
    throw Error("element " + std::to_string(point.element) + " does not exist");
  }
  int face = point.element;
  double u = point.u, v = point.v;
  for (int level = s.isolationLevels - 1; level >= 0; --level) {
    const auto [parent, child] = s.parentOf[level][face];
    face = parent;
    if (level == 0 && s.controlFaceSize[parent] != 4) {
      // A Ptex sub-face of an n-gon: same parameters.
      return SurfacePoint{s.parametricFaceOffset[parent] + child, u, v};
    }
    // Undo (u, v) = 2 cornerFrame(child, U, V); cornerFrame(4 - child) inverts cornerFrame(child).
    const auto [a, b] = detail::cornerFrame((4 - child) % 4, 0.5 * u, 0.5 * v);
    u = a;
    v = b;
  }
  return SurfacePoint{s.parametricFaceOffset[face], u, v};
}

namespace {

void checkPoints(const MatrixX3& controlPoints, int expected) {
  if (controlPoints.rows() != expected) {
    throw Error("got " + std::to_string(controlPoints.rows()) + " control points for a surface of " +
                std::to_string(expected) + " control vertices");
  }
}

}  // namespace

LimitSample LimitSurface::evaluate(const ElementPoint& point, const MatrixX3& controlPoints) const {
  checkPoints(controlPoints, impl_->controlVertexCount);
  return limitSampleOf(impl_->values(point, controlPoints));
}

LimitSample LimitSurface::evaluate(const SurfacePoint& point, const MatrixX3& controlPoints) const {
  checkPoints(controlPoints, impl_->controlVertexCount);
  Eigen::Matrix2d jacobian;
  const ElementPoint elementPoint = impl_->locate(point, jacobian);
  SampleWeights w = impl_->weights(elementPoint);
  applyChainRule(w, jacobian);
  const std::vector<int>& columns = impl_->columnsOf(elementPoint.element);
  Eigen::Matrix<double, 6, 3> values = Eigen::Matrix<double, 6, 3>::Zero();
  for (size_t c = 0; c < columns.size(); ++c) values.noalias() += w.col(c) * controlPoints.row(columns[c]);
  return limitSampleOf(values);
}

namespace {

// The rows of the first `count` operators (s, s_u, s_v, s_uu, s_uv, s_vv) at
// the points, as row-major sparse matrices built in place in one pass: each
// row's columns are its element's, already sorted, so no triplets are sorted
// or summed, and no point's weights are kept. A column whose weights are
// zero in every operator is left out; the operators share one pattern
// (applyOperators() reads it once for all).
// `jacobians`, if not empty, holds d(element u, v)/d(point's own u, v) per point.
// `weightsInto(point, w, count)` fills a point's weights (LimitSurface::Impl::weightsInto).
template <class WeightsInto>
std::array<SparseMatrix, 6> assemble(const LimitSurface& surface, const WeightsInto& weightsInto,
                                     const std::vector<ElementPoint>& points,
                                     const std::vector<Eigen::Matrix2d>& jacobians, int count) {
  std::array<SparseMatrix, 6> result;
  const int rows = static_cast<int>(points.size());
  size_t nonZeros = 0;
  for (const ElementPoint& point : points) nonZeros += surface.elementColumns(point.element).size();
  std::array<int, 6> cursor{};
  for (int q = 0; q < count; ++q) {
    result[q].resize(rows, surface.controlVertexCount());
    result[q].resizeNonZeros(static_cast<Eigen::Index>(nonZeros));
    result[q].outerIndexPtr()[0] = 0;
  }
  SampleWeights w;
  for (int r = 0; r < rows; ++r) {
    weightsInto(points[r], w, count);
    if (!jacobians.empty()) applyChainRule(w, jacobians[r], count);
    const std::vector<int>& cols = surface.elementColumns(points[r].element);
    for (size_t c = 0; c < cols.size(); ++c) {
      const auto column = w.col(static_cast<Eigen::Index>(c)).head(count);
      if ((column.array() == 0.0).all()) continue;
      for (int q = 0; q < count; ++q) {
        result[q].innerIndexPtr()[cursor[q]] = cols[c];
        result[q].valuePtr()[cursor[q]++] = column(q);
      }
    }
    for (int q = 0; q < count; ++q) result[q].outerIndexPtr()[r + 1] = cursor[q];
  }
  for (int q = 0; q < count; ++q) result[q].resizeNonZeros(cursor[q]);
  return result;
}

// Swap, not move: Eigen 3.4's SparseMatrix has no move constructor, and
// std::move would copy every operator.
LimitOperators toOperators(std::array<SparseMatrix, 6>& m) {
  LimitOperators result;
  result.J.swap(m[0]);
  result.Ju.swap(m[1]);
  result.Jv.swap(m[2]);
  result.Juu.swap(m[3]);
  result.Juv.swap(m[4]);
  result.Jvv.swap(m[5]);
  return result;
}

int operatorCount(int order) {
  if (order < 0 || order > 2) throw Error("limit operators have derivatives of order 0, 1 or 2, not " + std::to_string(order));
  return order == 0 ? 1 : order == 1 ? 3 : 6;
}

}  // namespace

LimitOperators LimitSurface::operators(const std::vector<ElementPoint>& points, int order) const {
  const auto weightsInto = [this](const ElementPoint& p, SampleWeights& w, int count) {
    impl_->weightsInto(p, w, count);
  };
  std::array<SparseMatrix, 6> m = assemble(*this, weightsInto, points, {}, operatorCount(order));
  return toOperators(m);
}

SparseMatrix LimitSurface::limitOperator(const std::vector<ElementPoint>& points) const {
  const auto weightsInto = [this](const ElementPoint& p, SampleWeights& w, int count) {
    impl_->weightsInto(p, w, count);
  };
  std::array<SparseMatrix, 6> m = assemble(*this, weightsInto, points, {}, 1);
  SparseMatrix result;
  result.swap(m[0]);
  return result;
}

LimitOperators LimitSurface::operators(const std::vector<SurfacePoint>& points, int order) const {
  const auto weightsInto = [this](const ElementPoint& p, SampleWeights& w, int count) {
    impl_->weightsInto(p, w, count);
  };
  const int count = operatorCount(order);
  std::vector<ElementPoint> at(points.size());
  std::vector<Eigen::Matrix2d> jacobians(points.size());
  for (size_t i = 0; i < points.size(); ++i) at[i] = impl_->locate(points[i], jacobians[i]);
  std::array<SparseMatrix, 6> m = assemble(*this, weightsInto, at, jacobians, count);
  return toOperators(m);
}

SparseMatrix LimitSurface::patchOperator() const {
  const Impl& s = *impl_;
  SparseMatrix result(16 * elementCount(), s.controlVertexCount);
  size_t nonZeros = 0;
  for (const Impl::Element& e : s.elements) {
    if (e.type == ElementType::Normal) nonZeros += 16 * e.columns.size();
  }
  result.resizeNonZeros(static_cast<Eigen::Index>(nonZeros));
  int* outer = result.outerIndexPtr();
  int* inner = result.innerIndexPtr();
  double* values = result.valuePtr();
  int k = 0;
  outer[0] = 0;
  for (size_t e = 0; e < s.elements.size(); ++e) {
    const Impl::Element& element = s.elements[e];
    for (int slot = 0; slot < 16; ++slot) {
      if (element.type == ElementType::Normal) {
        for (size_t c = 0; c < element.columns.size(); ++c) {
          if (element.grid(slot, static_cast<Eigen::Index>(c)) == 0.0) continue;
          inner[k] = element.columns[c];
          values[k] = element.grid(slot, static_cast<Eigen::Index>(c));
          ++k;
        }
      }
      outer[16 * e + slot + 1] = k;
    }
  }
  result.resizeNonZeros(k);
  return result;
}

const std::vector<int>& LimitSurface::elementColumns(int element) const {
  if (element < 0 || element >= elementCount()) throw Error("element " + std::to_string(element) + " does not exist");
  return impl_->columnsOf(element);
}

Eigen::Matrix<double, 6, Eigen::Dynamic> LimitSurface::stencil(const ElementPoint& point) const {
  return impl_->weights(point);
}

Eigen::RowVectorXd LimitSurface::positionStencil(const ElementPoint& point) const {
  SampleWeights w;
  impl_->weightsInto(point, w, 1);
  return w.row(0);
}

struct SurfaceState::Impl {
  static constexpr int kCachedLevels = 12;
  const LimitSurface* surface = nullptr;
  MatrixX3 controlPoints;
  // Built when first asked for: a tessellation needs only the grids, and on
  // a scan's mesh the operator takes a gigabyte.
  mutable std::once_flag patchOperatorOnce;
  mutable std::atomic<bool> patchOperatorBuilt{false};
  mutable SparseMatrix patchOperator;
  MatrixX3 grids;  // patchOperator * controlPoints
  // Per special element: the grid points of each subpatch a point has needed
  // at this state (slot 3 (level - 1) + child - 1; slot kSlots: the vertex
  // masks and the structure's vertices), each filled once under `mutex`. A
  // slot's grid is allocated the first time it is filled and kept, never
  // moved (reset() only marks it to be filled again): a reader that sees
  // ready[slot] set may read it without the lock.
  // One subpatch at a time, not whole levels: where most elements are
  // special and hold few points, filling all three children costs more than
  // it saves. And only the slots used are allocated: a tessellation touches
  // a few of an element's 36, and a scan's triangle mesh has a special
  // element on every face (448,128 for 75,408 triangles: 6 GB at 36 each).
  static constexpr int kSlots = 3 * kCachedLevels;
  using Grid = Eigen::Matrix<double, 16, 3>;
  struct Cache {
    std::array<std::atomic<bool>, kSlots + 1> ready{};
    std::mutex mutex;
    Eigen::Matrix<double, 3, 3> masks;               // limit position and tangents at the vertex
    Eigen::Matrix<double, Eigen::Dynamic, 3> local;  // the element's neighbourhood vertices
    std::array<std::unique_ptr<Grid>, kSlots> grids;
  };
  std::unique_ptr<Cache[]> caches;
};

SurfaceState::SurfaceState(const LimitSurface& surface) : impl_(std::make_unique<Impl>()) {
  impl_->surface = &surface;
  impl_->caches = std::make_unique<Impl::Cache[]>(surface.impl_->specials.size());
}

SurfaceState::~SurfaceState() = default;

void SurfaceState::reset(const MatrixX3& controlPoints) {
  checkPoints(controlPoints, impl_->surface->controlVertexCount());
  impl_->controlPoints = controlPoints;
  // patchOperator() * controlPoints: by the operator once it is built (its
  // rows are contiguous), else element by element from their grids, the
  // same products in the same order (the operator leaves out the grids'
  // zeros, which add nothing).
  if (impl_->patchOperatorBuilt.load(std::memory_order_acquire)) {
    applyOperator(impl_->patchOperator, controlPoints, impl_->grids);
  } else {
    const LimitSurface::Impl& s = *impl_->surface->impl_;
    impl_->grids.resize(16 * static_cast<Eigen::Index>(s.elements.size()), 3);
    Eigen::Matrix<double, 16, 3> grid;
    for (size_t e = 0; e < s.elements.size(); ++e) {
      const LimitSurface::Impl::Element& element = s.elements[e];
      if (element.type == ElementType::Normal)
        LimitSurface::Impl::blend(element.grid, element.columns, controlPoints, grid);
      else
        grid.setZero();  // the operator's rows of a special element are empty
      impl_->grids.middleRows<16>(16 * static_cast<Eigen::Index>(e)) = grid;
    }
  }
  for (size_t i = 0; i < impl_->surface->impl_->specials.size(); ++i) {
    for (std::atomic<bool>& r : impl_->caches[i].ready) r.store(false, std::memory_order_relaxed);
  }
}

const SparseMatrix& SurfaceState::patchOperator() const {
  std::call_once(impl_->patchOperatorOnce, [this] {
    impl_->patchOperator = impl_->surface->patchOperator();
    impl_->patchOperatorBuilt.store(true, std::memory_order_release);
  });
  return impl_->patchOperator;
}

const MatrixX3& SurfaceState::grids() const { return impl_->grids; }

LimitSample SurfaceState::evaluate(const ElementPoint& point) const {
  const LimitSurface::Impl& s = *impl_->surface->impl_;
  const MatrixX3& p = impl_->controlPoints;
  if (p.rows() != s.controlVertexCount) throw Error("internal: surface state used before reset()");
  s.checkPoint(point);
  const LimitSurface::Impl::Element& element = s.elements[point.element];
  if (element.type == ElementType::Normal) {
    // LazyProduct: Eigen sends the plain product to its blocked GEMM (a
    // grid block of a dynamic matrix has a runtime stride), whose packing
    // costs more than the 288 multiplications.
    return limitSampleOf(bicubicBsplineWeights(point.u, point.v)
                             .lazyProduct(impl_->grids.middleRows<16>(16 * static_cast<Eigen::Index>(point.element))));
  }
  const LimitSurface::Impl::SubpatchPoint at = s.locateSubpatch(element, point, false);
  if (at.level == 0 || at.level > Impl::kCachedLevels) return limitSampleOf(s.values(point, p));
  LimitSurface::Impl::Special& special = *s.specials[element.special];
  Impl::Cache& cache = impl_->caches[element.special];
  const int slot = 3 * (at.level - 1) + at.child - 1;
  if (!cache.ready[slot].load(std::memory_order_acquire) || !cache.ready[Impl::kSlots].load(std::memory_order_acquire)) {
    const std::lock_guard<std::mutex> lock(cache.mutex);
    if (!cache.ready[Impl::kSlots].load(std::memory_order_relaxed)) {
      LimitSurface::Impl::blend(special.vertexMasks, special.columns, p, cache.masks);
      s.neighbourhoodPoints(element, p, cache.local);
      cache.ready[Impl::kSlots].store(true, std::memory_order_release);
    }
    if (!cache.ready[slot].load(std::memory_order_relaxed)) {
      if (!cache.grids[slot]) cache.grids[slot] = std::make_unique<Impl::Grid>();
      cache.grids[slot]->noalias() = s.level(*s.structures[element.structure], at.level)[at.child - 1] * cache.local;
      cache.ready[slot].store(true, std::memory_order_release);
    }
  }
  Eigen::Matrix<double, 6, 3> result = detail::bsplineWeights(at.u, at.v) * *cache.grids[slot];
  result.row(0) += cache.masks.row(0);
  applyChainRule(result, at.jacobian);
  return limitSampleOf(result);
}

LimitSample limitSampleOf(const Eigen::Matrix<double, 6, 3>& values) {
  LimitSample sample;
  sample.position = values.row(0).transpose();
  sample.du = values.row(1).transpose();
  sample.dv = values.row(2).transpose();
  sample.duu = values.row(3).transpose();
  sample.duv = values.row(4).transpose();
  sample.dvv = values.row(5).transpose();
  const Vector3 normal = sample.du.cross(sample.dv);
  const double length = normal.norm();
  sample.normal = length > 0.0 ? Vector3(normal / length) : Vector3::Zero();
  return sample;
}

Eigen::Matrix<double, 6, 16> bicubicBsplineWeights(double a, double b) { return detail::bsplineWeights(a, b); }

ElementPieces LimitSurface::elementPieces(int element, int levels) const {
  const Impl& s = *impl_;
  if (element < 0 || element >= elementCount()) throw Error("element " + std::to_string(element) + " does not exist");
  if (levels < 1 || levels > 60) throw Error("special elements are split into 1..60 levels, not " + std::to_string(levels));
  const Impl::Element& e = s.elements[element];
  if (e.type == ElementType::Normal) {
    ElementPieces result;
    result.columns = e.columns;
    result.pieces.push_back(BsplinePiece{e.grid, Eigen::RowVectorXd::Zero(e.columns.size()), 1.0, false});
    return result;
  }
  // Its structure's pieces times its blends of its columns.
  const SharedPieces shared = sharedPieces(element, levels);
  ElementPieces result;
  result.columns = e.columns;
  for (const BsplinePiece& piece : shared.pieces->pieces) {
    result.pieces.push_back(
        BsplinePiece{piece.grid * shared.map, s.specials[e.special]->vertexMasks.row(0), piece.size, piece.swapped});
  }
  return result;
}

SharedPieces LimitSurface::sharedPieces(int element, int levels) const {
  const Impl& s = *impl_;
  if (element < 0 || element >= elementCount()) throw Error("element " + std::to_string(element) + " does not exist");
  if (levels < 1 || levels > 60) throw Error("special elements are split into 1..60 levels, not " + std::to_string(levels));
  const Impl::Element& e = s.elements[element];
  if (e.type == ElementType::Normal) throw Error("internal: element " + std::to_string(element) + " is not special");
  const std::array<int, 3> key{e.structure, e.corner, levels};
  const std::lock_guard<std::mutex> lock(s.structurePiecesMutex);
  auto found = s.structurePieces.find(key);
  if (found == s.structurePieces.end()) {
    found = s.structurePieces.emplace(key, s.piecesOf(*s.structures[e.structure], e.corner, levels)).first;
  }
  // A std::map's elements never move: the pointer stays valid as others are added.
  return SharedPieces{(e.structure * 4 + e.corner) * 61 + levels, &found->second, s.structureMap(e)};
}

SparseMatrix LimitSurface::controlVertexLimitOperator() const {
  const Impl& s = *impl_;
  std::vector<Triplet> triplets;
  // Control vertex i is vertex i of the base mesh (refinement keeps vertex numbers).
  for (int i = 0; i < s.meshVertexCount; ++i) {
    const detail::VertexMasks masks = detail::vertexMasks(s.base, i, s.base.vertexFaces(i).front());
    for (const auto& [b, w] : masks.position) {
      for (SparseMatrix::InnerIterator it(s.isolation, b); it; ++it) triplets.emplace_back(i, it.col(), w * it.value());
    }
  }
  SparseMatrix result(s.meshVertexCount, s.controlVertexCount);
  result.setFromTriplets(triplets.begin(), triplets.end());
  return result;
}

}  // namespace dynsub
