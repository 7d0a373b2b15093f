#include "dynsub/Integrator.h"

#include <cmath>
#include <string>

#include <Eigen/IterativeLinearSolvers>

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

struct Integrator::Impl {
  IntegratorOptions options;
  SymmetricMatrix mass, damping, forceStiffness;
  std::vector<int> freeIndex;                // free position of each vertex, or -1
  std::vector<int> freeVertices;
  SymmetricMatrix lhsFree, lhsCoupling;      // free x free, free x fixed
  SparseCholesky cholesky;
  Eigen::ConjugateGradient<SymmetricMatrix, Eigen::Lower | Eigen::Upper, Eigen::IdentityPreconditioner> cg;
  Eigen::ConjugateGradient<SymmetricMatrix, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> pcg;
  int iterations = 0;
};

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
  const int n = static_cast<int>(matrices.mass.rows());
  s.mass = matrices.mass;
  s.damping = matrices.damping;
  SymmetricMatrix stiffness = matrices.stiffness;
  if (forceStiffness.size() > 0) {
    if (forceStiffness.rows() != n || forceStiffness.cols() != n) {
      throw Error("internal: force stiffness has the wrong size");
    }
    s.forceStiffness = forceStiffness;
    stiffness += forceStiffness;
  }
  s.freeIndex.assign(n, 0);
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

  const SymmetricMatrix lhs = options.scheme == IntegrationScheme::SecondOrder
                                  ? SymmetricMatrix(2.0 * s.mass + dt * s.damping + 2.0 * dt * dt * stiffness)
                                  : SymmetricMatrix(s.damping + 2.0 * dt * stiffness);
  s.lhsFree = select(lhs, s.freeIndex, free, s.freeIndex, free);
  s.lhsCoupling = select(lhs, s.freeIndex, free, fixedIndex, pinned);
  s.lhsFree.makeCompressed();

  switch (options.solver) {
    case LinearSolver::Cholesky:
      s.cholesky.analyzePattern(s.lhsFree);
      // NB: a singular matrix (K alone: translations cost nothing) factors with
      // pivots at rounding level rather than failing; those count as zero.
      if (!s.cholesky.factorize(s.lhsFree)) {
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

Matrix3X Integrator::step(const Matrix3X& previous, const Matrix3X& current, const Matrix3X& force) {
  Impl& s = *impl_;
  const double dt = s.options.timeStep;
  // The force stiffness S is on the left; S p(t) joins the force on the right.
  Matrix3X stabilizedForce = force;
  if (s.forceStiffness.size() > 0) stabilizedForce += s.forceStiffness * current;
  Matrix3X rhs;
  if (s.options.scheme == IntegrationScheme::SecondOrder) {
    rhs = 2.0 * dt * dt * stabilizedForce + (dt * (s.damping * previous) - 2.0 * (s.mass * previous)) +
          4.0 * (s.mass * current);
  } else {
    rhs = 2.0 * dt * stabilizedForce + s.damping * previous;
  }
  Matrix3X next = current;
  const int free = static_cast<int>(s.freeVertices.size());
  Eigen::MatrixXd rhsFree(free, 3), guess(free, 3), pinned(s.lhsCoupling.cols(), 3);
  for (int i = 0; i < free; ++i) {
    rhsFree.row(i) = rhs.row(s.freeVertices[i]);
    guess.row(i) = current.row(s.freeVertices[i]);
  }
  for (int v = 0, k = 0; v < static_cast<int>(s.freeIndex.size()); ++v) {
    if (s.freeIndex[v] < 0) pinned.row(k++) = current.row(v);
  }
  if (pinned.rows() > 0) rhsFree -= s.lhsCoupling * pinned;

  Eigen::MatrixXd solution(free, 3);
  s.iterations = 0;
  // x, y and z one after the other, each from last step's solution.
  auto iterate = [&](auto& solver, const char* name) {
    for (int c = 0; c < 3; ++c) {
      solution.col(c) = solver.solveWithGuess(rhsFree.col(c), guess.col(c));
      s.iterations += static_cast<int>(solver.iterations());
      if (solver.info() != Eigen::Success) throw Error(std::string(name) + " did not converge");
    }
  };
  switch (s.options.solver) {
    case LinearSolver::Cholesky:
      solution = s.cholesky.solve(rhsFree);
      break;
    case LinearSolver::ConjugateGradient:
      iterate(s.cg, "conjugate gradients");
      break;
    case LinearSolver::PreconditionedConjugateGradient:
      iterate(s.pcg, "preconditioned conjugate gradients");
      break;
  }
  for (int i = 0; i < free; ++i) next.row(s.freeVertices[i]) = solution.row(i);
  return next;
}

int Integrator::lastIterations() const { return impl_->iterations; }
const IntegratorOptions& Integrator::options() const { return impl_->options; }

}  // namespace dynsub
