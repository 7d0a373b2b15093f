#include "dynsub/Integrator.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/IterativeLinearSolvers>

#include "PairedProduct.h"
#include "SparseCholesky.h"
#include "dynsub/Error.h"

namespace dynsub {

const char* toString(IntegrationScheme scheme) {
  switch (scheme) {
    case IntegrationScheme::SecondOrder: return "second-order";
    case IntegrationScheme::FirstOrder: return "first-order";
    default: return "static";
  }
}

const char* toString(LinearSolver solver) {
  switch (solver) {
    case LinearSolver::Cholesky: return "cholesky";
    case LinearSolver::ConjugateGradient: return "cg";
    default: return "pcg";
  }
}

IntegrationScheme parseIntegrationScheme(const std::string& text) {
  if (text == "second-order") return IntegrationScheme::SecondOrder;
  if (text == "first-order") return IntegrationScheme::FirstOrder;
  if (text == "static") return IntegrationScheme::Static;
  throw Error("unknown integration scheme '" + text + "' (expected second-order, first-order or static)");
}

LinearSolver parseLinearSolver(const std::string& text) {
  if (text == "cholesky") return LinearSolver::Cholesky;
  if (text == "cg") return LinearSolver::ConjugateGradient;
  if (text == "pcg") return LinearSolver::PreconditionedConjugateGradient;
  throw Error("unknown linear solver '" + text + "' (expected cholesky, cg or pcg)");
}

namespace {

// Rows and columns of `m` picked by `rows` and `columns` index lists (-1: dropped).
SymmetricMatrix select(const SymmetricMatrix& m, const std::vector<int>& rowIndex, int rows,
                       const std::vector<int>& columnIndex, int columns) {
  std::vector<Eigen::Triplet<double>> triplets;
  for (int c = 0; c < m.outerSize(); ++c) {
    if (columnIndex[c] < 0) continue;
    for (SymmetricMatrix::InnerIterator it(m, c); it; ++it) {
      const int r = rowIndex[it.row()];
      if (r >= 0) triplets.emplace_back(r, columnIndex[c], it.value());
    }
  }
  SymmetricMatrix result(rows, columns);
  result.setFromTriplets(triplets.begin(), triplets.end());
  return result;
}

}  // namespace

struct Integrator::Impl {
  IntegratorOptions options;
  // The right-hand side is forceWeight f + C p(t) + P p(t-dt).
  double forceWeight = 0.0;
  PairedProduct rightHandSide;
  MatrixX3 rhs;                              // the right-hand side, by vertex
  std::vector<int> freeIndex;                // free position of each vertex, or -1
  std::vector<int> freeVertices;
  SymmetricMatrix lhsFree, lhsCoupling;      // free x free, free x fixed
  SparseCholesky cholesky;
  Eigen::ConjugateGradient<SymmetricMatrix, Eigen::Lower | Eigen::Upper, Eigen::IdentityPreconditioner> cg;
  Eigen::ConjugateGradient<SymmetricMatrix, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> pcg;
  int iterations = 0;
  // Added to the diagonals of M and D once a left-hand matrix was singular
  // (below); 0 until then.
  double diagonalShift = 0.0;

  // The matrices of both sides for `forceStiffness` (Integrator.h); the
  // factorization's analysis is redone only when `analyze` or when the
  // left-hand pattern changed.
  void build(const PhysicalMatrices& matrices, const SymmetricMatrix& forceStiffness, const std::vector<int>& fixed,
             bool analyze);
};


Integrator::Integrator(const PhysicalMatrices& matrices, const SymmetricMatrix& forceStiffness,
                       const std::vector<int>& fixed, const IntegratorOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = options;
  const double dt = options.timeStep;
  if (!(std::isfinite(dt) && dt > 0.0)) throw Error("time step must be positive, got " + std::to_string(dt));
  if (options.scheme == IntegrationScheme::Static) throw Error("internal: the static scheme is not a time integration");
  if (!(options.solverTolerance > 0.0) || options.solverMaxIterations < 1) {
    throw Error("iterative solver tolerance must be > 0 and iterations >= 1");
  }
  s.build(matrices, forceStiffness, fixed, true);
}

void Integrator::restabilize(const PhysicalMatrices& matrices, const SymmetricMatrix& forceStiffness) {
  Impl& s = *impl_;
  if (matrices.mass.rows() != static_cast<Eigen::Index>(s.freeIndex.size())) {
    throw Error("internal: restabilized with matrices of another size");
  }
  std::vector<int> fixed;
  for (int v = 0; v < static_cast<int>(s.freeIndex.size()); ++v) {
    if (s.freeIndex[v] < 0) fixed.push_back(v);
  }
  s.build(matrices, forceStiffness, fixed, false);
}

void Integrator::Impl::build(const PhysicalMatrices& matrices, const SymmetricMatrix& forceStiffness,
                             const std::vector<int>& fixed, bool analyze) {
  Impl& s = *this;
  const double dt = options.timeStep;
  const int n = static_cast<int>(matrices.mass.rows());
  SymmetricMatrix stiffness = matrices.stiffness;
  SymmetricMatrix stabilizing(n, n);
  if (forceStiffness.size() > 0) {
    if (forceStiffness.rows() != n || forceStiffness.cols() != n) {
      throw Error("internal: force stiffness has the wrong size");
    }
    stabilizing = forceStiffness;
    stiffness += forceStiffness;
  }
  // The force stiffness S is on the left; S p(t) joins the force on the right:
  //   second order: 2 dt^2 (f + S p(t)) + 4 M p(t) + (D dt - 2M) p(t-dt)
  //   first order:  2 dt (f + S p(t)) + D p(t-dt)
  const bool second = options.scheme == IntegrationScheme::SecondOrder;
  SymmetricMatrix mass = matrices.mass, damping = matrices.damping;
  for (int d = 0; d < n && s.diagonalShift > 0.0; ++d) {
    mass.coeffRef(d, d) += s.diagonalShift;
    damping.coeffRef(d, d) += s.diagonalShift;
  }
  s.forceWeight = second ? 2.0 * dt * dt : 2.0 * dt;
  const SymmetricMatrix onCurrent =
      second ? SymmetricMatrix(s.forceWeight * stabilizing + 4.0 * mass) : SymmetricMatrix(s.forceWeight * stabilizing);
  const SymmetricMatrix onPrevious = second ? SymmetricMatrix(dt * damping - 2.0 * mass) : damping;
  s.rightHandSide = PairedProduct(onCurrent, onPrevious);
  s.freeIndex.assign(n, 0);
  s.freeVertices.clear();
  for (int v : fixed) {
    if (v < 0 || v >= n) throw Error("fixed control vertex " + std::to_string(v) + " does not exist");
    s.freeIndex[v] = -1;
  }
  std::vector<int> fixedIndex(n, -1);
  int free = 0, pinned = 0;
  for (int v = 0; v < n; ++v) {
    if (s.freeIndex[v] >= 0) {
      s.freeIndex[v] = free++;
      s.freeVertices.push_back(v);
    } else {
      fixedIndex[v] = pinned++;
    }
  }
  if (free == 0) throw Error("every control vertex is fixed: nothing can move");

  const SymmetricMatrix lhs = second ? SymmetricMatrix(2.0 * mass + dt * damping + 2.0 * dt * dt * stiffness)
                                     : SymmetricMatrix(damping + 2.0 * dt * stiffness);
  SymmetricMatrix lhsFree = select(lhs, s.freeIndex, free, s.freeIndex, free);
  lhsFree.makeCompressed();
  // The stabilizer's updates (Simulation.h) change only values: its
  // stiffness lies within the elements' pattern, which K and D fill.
  const bool samePattern =
      !analyze && lhsFree.rows() == s.lhsFree.rows() && lhsFree.nonZeros() == s.lhsFree.nonZeros() &&
      std::equal(lhsFree.outerIndexPtr(), lhsFree.outerIndexPtr() + lhsFree.outerSize() + 1, s.lhsFree.outerIndexPtr()) &&
      std::equal(lhsFree.innerIndexPtr(), lhsFree.innerIndexPtr() + lhsFree.nonZeros(), s.lhsFree.innerIndexPtr());
  s.lhsFree = std::move(lhsFree);
  s.lhsCoupling = select(lhs, s.freeIndex, free, fixedIndex, pinned);

  switch (options.solver) {
    case LinearSolver::Cholesky:
      if (!samePattern) s.cholesky.analyzePattern(s.lhsFree);
      // A singular matrix (K alone: translations cost nothing) factors with
      // pivots at rounding level rather than failing; those count as zero.
      if (!s.cholesky.factorize(s.lhsFree)) {
        // Some control meshes have motions of their control points that the
        // limit surface does not show (the 8-vertex cube: its vertices moved
        // by +d and -d alternately leave the limit surface where it is), so
        // M and D, integrals over the surface, are singular for them. A
        // shift of 1e-9 of D's mean diagonal on M and D alike holds such a
        // motion still and changes the visible ones by rounding only.
        const double meanDiagonal = matrices.damping.diagonal().cwiseAbs().mean();
        if (s.diagonalShift == 0.0 && meanDiagonal > 0.0) {
          s.diagonalShift = 1e-9 * meanDiagonal;
          build(matrices, forceStiffness, fixed, analyze);
          return;
        }
        throw Error("the left-hand matrix of the time step is not positive definite (is the surface anchored? "
                    "first-order integration needs damping > 0)");
      }
      break;
    case LinearSolver::ConjugateGradient:
      s.cg.setTolerance(options.solverTolerance);
      s.cg.setMaxIterations(options.solverMaxIterations);
      s.cg.compute(s.lhsFree);
      if (s.cg.info() != Eigen::Success) throw Error("conjugate gradients could not be set up");
      break;
    case LinearSolver::PreconditionedConjugateGradient:
      s.pcg.setTolerance(options.solverTolerance);
      s.pcg.setMaxIterations(options.solverMaxIterations);
      s.pcg.compute(s.lhsFree);
      if (s.pcg.info() != Eigen::Success) throw Error("the incomplete Cholesky preconditioner failed");
      break;
  }
}

Integrator::~Integrator() = default;
Integrator::Integrator(Integrator&&) noexcept = default;
Integrator& Integrator::operator=(Integrator&&) noexcept = default;

MatrixX3 Integrator::step(const MatrixX3& previous, const MatrixX3& current, const MatrixX3& force) {
  Impl& s = *impl_;
  const int free = static_cast<int>(s.freeVertices.size());
  const int vertices = static_cast<int>(s.freeIndex.size());
  Eigen::MatrixXd pinned(s.lhsCoupling.cols(), 3);
  for (int v = 0, k = 0; v < vertices; ++v) {
    if (s.freeIndex[v] < 0) pinned.row(k++) = current.row(v);
  }
  s.iterations = 0;
  s.rightHandSide.apply(s.forceWeight, force, current, previous, s.rhs);
  MatrixX3 next = current;
  Eigen::MatrixXd rhsFree(free, 3);
  for (int i = 0; i < free; ++i) rhsFree.row(i) = s.rhs.row(s.freeVertices[i]);
  if (pinned.rows() > 0) rhsFree -= s.lhsCoupling * pinned;
  Eigen::MatrixXd solution(free, 3);
  // x, y and z one after the other, each from last step's solution.
  auto iterate = [&](auto& solver, const char* name) {
    Eigen::MatrixXd guess(free, 3);
    for (int i = 0; i < free; ++i) guess.row(i) = current.row(s.freeVertices[i]);
    for (int c = 0; c < 3; ++c) {
      solution.col(c) = solver.solveWithGuess(rhsFree.col(c), guess.col(c));
      s.iterations += static_cast<int>(solver.iterations());
      if (solver.info() != Eigen::Success) throw Error(std::string(name) + " did not converge");
    }
  };
  switch (s.options.solver) {
    case LinearSolver::Cholesky: solution = s.cholesky.solve(rhsFree); break;
    case LinearSolver::ConjugateGradient: iterate(s.cg, "conjugate gradients"); break;
    case LinearSolver::PreconditionedConjugateGradient: iterate(s.pcg, "preconditioned conjugate gradients"); break;
  }
  for (int i = 0; i < free; ++i) next.row(s.freeVertices[i]) = solution.row(i);
  return next;
}

int Integrator::lastIterations() const { return impl_->iterations; }
const IntegratorOptions& Integrator::options() const { return impl_->options; }

}  // namespace dynsub
