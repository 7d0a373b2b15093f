#include "dynsub/PhysicalMatrices.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "dynsub/Error.h"
#include "dynsub/GaussLegendre.h"
#include "dynsub/LimitSurface.h"

namespace dynsub {

namespace {

using Matrix16 = Eigen::Matrix<double, 16, 16>;

// ∫∫ over the unit square of B^T B for the six basis rows (s, s_a, s_b, s_aa, s_ab, s_bb).
struct UnitIntegrals {
  std::array<Matrix16, 6> rows;
};

UnitIntegrals unitIntegrals(int points) {
  const QuadratureRule rule = gaussLegendre(points);
  UnitIntegrals result;
  for (Matrix16& m : result.rows) m.setZero();
  for (int i = 0; i < points; ++i) {
    for (int j = 0; j < points; ++j) {
      const Eigen::Matrix<double, 6, 16> w = bicubicBsplineWeights(rule.nodes[i], rule.nodes[j]);
      const double weight = rule.weights[i] * rule.weights[j];
      for (int r = 0; r < 6; ++r) result.rows[r].noalias() += weight * w.row(r).transpose() * w.row(r);
    }
  }
  return result;
}

// The unit integrals depend only on the quadrature order; the default's are cached.
const UnitIntegrals& exactUnitIntegrals() {
  static const UnitIntegrals exact = unitIntegrals(4);
  return exact;
}

void checkOptions(const AssemblyOptions& options) {
  if (!(std::isfinite(options.elementSize) && options.elementSize > 0.0)) {
    throw Error("element size must be positive, got " + std::to_string(options.elementSize));
  }
  if (options.levels < 1 || options.levels > 60) {
    throw Error("special elements take 1..60 levels, got " + std::to_string(options.levels));
  }
  if (options.plateLevels < 0 || options.plateLevels > options.levels) {
    throw Error("plate levels must be in 0.." + std::to_string(options.levels) + ", got " +
                std::to_string(options.plateLevels));
  }
  if (options.quadraturePoints < 4 || options.quadraturePoints > 64) {
    throw Error("B-spline pieces need 4..64 quadrature points per direction to be exact, got " +
                std::to_string(options.quadraturePoints));
  }
}

}  // namespace

void checkMaterial(const Material& m) {
  const double values[] = {m.mass, m.damping, m.tensionU, m.tensionV, m.rigidityUU, m.rigidityUV, m.rigidityVV};
  const char* names[] = {"mass", "damping", "tension u", "tension v", "rigidity uu", "rigidity uv", "rigidity vv"};
  for (int i = 0; i < 7; ++i) requireFiniteNonNegative(values[i], std::string("material ") + names[i]);
}

namespace {

// The integrals over `pieces` (a normal element's one piece, or a special
// element's levels), over the pieces' columns.
ElementIntegrals integratePieces(const ElementPieces& pieces, bool special, const AssemblyOptions& options) {
  const UnitIntegrals unit = options.quadraturePoints == 4 ? exactUnitIntegrals() : unitIntegrals(options.quadraturePoints);
  const int n = static_cast<int>(pieces.pieces.empty() ? 0 : pieces.pieces.front().grid.cols());
  ElementIntegrals result;
  result.columns = pieces.columns;
  for (Eigen::MatrixXd* m : {&result.mass, &result.tensionU, &result.tensionV, &result.plateUU, &result.plateUV,
                             &result.plateVV}) {
    m->setZero(n, n);
  }
  for (size_t k = 0; k < pieces.pieces.size(); ++k) {
    const BsplinePiece& piece = pieces.pieces[k];
    const int level = special ? static_cast<int>(k / 3) + 1 : 0;
    const double side = piece.size * options.elementSize;
    const auto& grid = piece.grid;  // the derivatives see only the displacements
    const Eigen::MatrixXd points = grid.rowwise() + piece.offset;
    // Element u is the piece's a unless the piece is turned a quarter.
    const int firstU = piece.swapped ? 2 : 1, firstV = piece.swapped ? 1 : 2;
    const int secondUU = piece.swapped ? 5 : 3, secondVV = piece.swapped ? 3 : 5;
    result.mass.noalias() += side * side * (points.transpose() * unit.rows[0] * points);
    result.tensionU.noalias() += grid.transpose() * unit.rows[firstU] * grid;
    result.tensionV.noalias() += grid.transpose() * unit.rows[firstV] * grid;
    if (!special || level <= options.plateLevels) {
      const double scale = 1.0 / (side * side);
      result.plateUU.noalias() += scale * (grid.transpose() * unit.rows[secondUU] * grid);
      result.plateUV.noalias() += scale * (grid.transpose() * unit.rows[4] * grid);
      result.plateVV.noalias() += scale * (grid.transpose() * unit.rows[secondVV] * grid);
    }
  }
  return result;
}

// For a grid that is a permutation of 16 columns (a normal element away from
// the boundary: its 16 B-spline control points are its control vertices), the
// slot of each column; empty otherwise.
std::vector<int> permutationSlots(const Eigen::Matrix<double, 16, Eigen::Dynamic>& grid) {
  if (grid.cols() != 16) return {};
  std::vector<int> slots(16, -1);
  for (int slot = 0; slot < 16; ++slot) {
    for (int column = 0; column < 16; ++column) {
      const double w = grid(slot, column);
      if (w == 0.0) continue;
      if (w != 1.0 || slots[column] >= 0) return {};
      slots[column] = slot;
    }
  }
  if (std::find(slots.begin(), slots.end(), -1) != slots.end()) return {};
  return slots;
}

// A normal element's integrals when its grid is a permutation P: each
// P^T U P is U's entries rearranged, the same values the products give (their
// other terms are exact zeros), without the 12 dense 16 x 16 products.
// The dense products would be a sizeable share of the assembly.
ElementIntegrals permutedIntegrals(const UnitIntegrals& unit, const std::vector<int>& slots,
                                   const std::vector<int>& columns, double side) {
  ElementIntegrals result;
  result.columns = columns;
  auto rearranged = [&](const Matrix16& u, double scale) {
    Eigen::MatrixXd m(16, 16);
    for (int j = 0; j < 16; ++j) {
      for (int i = 0; i < 16; ++i) m(i, j) = scale * u(slots[i], slots[j]);
    }
    return m;
  };
  result.mass = rearranged(unit.rows[0], side * side);
  result.tensionU = rearranged(unit.rows[1], 1.0);
  result.tensionV = rearranged(unit.rows[2], 1.0);
  const double scale = 1.0 / (side * side);
  result.plateUU = rearranged(unit.rows[3], scale);
  result.plateUV = rearranged(unit.rows[4], scale);
  result.plateVV = rearranged(unit.rows[5], scale);
  return result;
}

// Integrals over a structure's neighbourhood vertices carried to an
// element's columns: the pieces are the shared ones times `map`, so each
// integral G^T U G becomes map^T (G^T U G) map.
ElementIntegrals mapIntegrals(const ElementIntegrals& shared, const Eigen::MatrixXd& map,
                              const std::vector<int>& columns) {
  ElementIntegrals result;
  result.columns = columns;
  result.mass = map.transpose() * shared.mass * map;
  result.tensionU = map.transpose() * shared.tensionU * map;
  result.tensionV = map.transpose() * shared.tensionV * map;
  result.plateUU = map.transpose() * shared.plateUU * map;
  result.plateUV = map.transpose() * shared.plateUV * map;
  result.plateVV = map.transpose() * shared.plateVV * map;
  return result;
}

// One element's integrals; a special element's through its structure's,
// integrated once per structure in `cache` (by SharedPieces::key).
ElementIntegrals integrate(const LimitSurface& surface, int element, const AssemblyOptions& options,
                           std::map<int, ElementIntegrals>& cache) {
  if (surface.elementType(element) == ElementType::Normal) {
    const ElementPieces pieces = surface.elementPieces(element, 1);
    const BsplinePiece& piece = pieces.pieces.front();
    const std::vector<int> slots = permutationSlots(piece.grid);
    if (!slots.empty() && !piece.swapped && options.quadraturePoints == 4) {
      return permutedIntegrals(exactUnitIntegrals(), slots, pieces.columns, piece.size * options.elementSize);
    }
    return integratePieces(pieces, false, options);
  }
  const SharedPieces shared = surface.sharedPieces(element, options.levels);
  auto found = cache.find(shared.key);
  if (found == cache.end()) found = cache.emplace(shared.key, integratePieces(*shared.pieces, true, options)).first;
  return mapIntegrals(found->second, shared.map, surface.elementColumns(element));
}

}  // namespace

ElementIntegrals integrateElement(const LimitSurface& surface, int element, const AssemblyOptions& options) {
  checkOptions(options);
  std::map<int, ElementIntegrals> cache;
  return integrate(surface, element, options, cache);
}

SymmetricMatrix elementPattern(const LimitSurface& surface) {
  const int vertices = surface.controlVertexCount(), elements = surface.elementCount();
  // The elements of each control vertex, in increasing order.
  std::vector<int> firstElement(vertices + 1, 0);
  for (int e = 0; e < elements; ++e) {
    const std::vector<int>& columns = surface.elementColumns(e);
    if (!std::is_sorted(columns.begin(), columns.end())) throw Error("internal: element columns are not sorted");
    for (int j : columns) ++firstElement[j + 1];
  }
  for (int j = 0; j < vertices; ++j) firstElement[j + 1] += firstElement[j];
  std::vector<int> elementsOf(firstElement.back());
  std::vector<int> next(firstElement.begin(), firstElement.end() - 1);
  for (int e = 0; e < elements; ++e)
    for (int j : surface.elementColumns(e)) elementsOf[next[j]++] = e;
  // Each column's rows are gathered once each (a stamp per vertex marks
  // the rows seen) and only those sorted: appending every element's columns
  // would repeat each row up to tenfold on an isolated mesh, all to be sorted
  // out again (this pattern is also the Newton matrix's).
  std::vector<int> outer(vertices + 1, 0), inner, seen(vertices, -1);
  for (int j = 0; j < vertices; ++j) {
    const auto begin = inner.size();
    for (int k = firstElement[j]; k < firstElement[j + 1]; ++k)
      for (int i : surface.elementColumns(elementsOf[k]))
        if (seen[i] != j) seen[i] = j, inner.push_back(i);
    std::sort(inner.begin() + static_cast<long>(begin), inner.end());
    outer[j + 1] = static_cast<int>(inner.size());
  }
  SymmetricMatrix pattern(vertices, vertices);
  pattern.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), pattern.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), pattern.innerIndexPtr());
  std::fill(pattern.valuePtr(), pattern.valuePtr() + inner.size(), 0.0);
  return pattern;
}

PhysicalMatrices assemblePhysicalMatrices(const LimitSurface& surface, const std::vector<Material>& materials,
                                          const AssemblyOptions& options) {
  checkOptions(options);
  const int elements = surface.elementCount();
  if (materials.size() != 1 && static_cast<int>(materials.size()) != elements) {
    throw Error("got " + std::to_string(materials.size()) + " materials for a surface of " +
                std::to_string(elements) + " elements (give one, or one per element)");
  }
  for (const Material& m : materials) checkMaterial(m);

  // Summed in place on the pattern of every pair of control vertices
  // sharing an element, in element order: setFromTriplets would need m^2
  // triplets per matrix and element, millions on a fine mesh, and building
  // and sorting them would cost more than the integrals.
  const SymmetricMatrix pattern = elementPattern(surface);
  PhysicalMatrices result;
  result.mass = pattern;
  result.damping = pattern;
  result.stiffness = pattern;
  const int* outer = pattern.outerIndexPtr();
  const int* inner = pattern.innerIndexPtr();
  std::map<int, ElementIntegrals> shared;
  for (int e = 0; e < elements; ++e) {
    const Material& m = materials.size() == 1 ? materials[0] : materials[e];
    const ElementIntegrals integrals = integrate(surface, e, options, shared);
    const Eigen::MatrixXd k = m.tensionU * integrals.tensionU + m.tensionV * integrals.tensionV +
                              m.rigidityUU * integrals.plateUU + m.rigidityUV * integrals.plateUV +
                              m.rigidityVV * integrals.plateVV;
    const std::vector<int>& columns = integrals.columns;
    const int n = static_cast<int>(columns.size());
    for (int j = 0; j < n; ++j) {
      // The element's rows are sorted, so one walk down the column finds them all.
      int position = outer[columns[j]];
      for (int i = 0; i < n; ++i) {
        while (inner[position] != columns[i]) ++position;
        result.mass.valuePtr()[position] += m.mass * integrals.mass(i, j);
        result.damping.valuePtr()[position] += m.damping * integrals.mass(i, j);
        result.stiffness.valuePtr()[position] += k(i, j);
      }
    }
  }
  return result;
}

PhysicalMatrices assemblePhysicalMatrices(const LimitSurface& surface, const Material& material,
                                          const AssemblyOptions& options) {
  return assemblePhysicalMatrices(surface, std::vector<Material>{material}, options);
}

}  // namespace dynsub
