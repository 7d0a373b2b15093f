#include "dynsub/StaticSolver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>

#include "dynsub/ParallelFor.h"
#include "SparseCholesky.h"
#include "dynsub/Error.h"
#include "dynsub/ForceModel.h"

namespace dynsub {

namespace {

// Unknown 3 v + a as row v, column a.
MatrixX3 toPoints(const Eigen::VectorXd& x, size_t vertices) {
  MatrixX3 points(vertices, 3);
  for (size_t v = 0; v < vertices; ++v) {
    for (int a = 0; a < 3; ++a) points(static_cast<Eigen::Index>(v), a) = x(static_cast<Eigen::Index>(3 * v + a));
  }
  return points;
}

}  // namespace

struct StaticSolver::Impl {
  TangentStiffness tangent;  // K from construction on; a direction adds the forces' stiffness
  std::vector<bool> fixed;
  SparseCholesky factor;
  bool analysed = false;
  bool factored = false;  // `factor` holds some earlier step's matrix
  int regularizations = 0;
  // Steps to factor directly before trying the earlier factor again, and the
  // next such wait: it doubles with each failed try (up to 16 steps) and
  // returns to 1 after one that converged.
  // Early in a fit, while H changes fast, the earlier factor seldom
  // preconditions well enough, and each failed try costs its iterations on
  // top of the factorization; the growing wait keeps such tries few.
  int skip = 0, backoff = 1;

  // Conjugate gradients on h x = rhs preconditioned by the earlier step's
  // factor; true when they reach kReuseTolerance within kReuseIterations.
  bool solveWithEarlierFactor(const SymmetricMatrix& h, const Eigen::VectorXd& rhs, Eigen::VectorXd& x) const {
    x = factor.solve(rhs);
    Eigen::VectorXd r = rhs - h.selfadjointView<Eigen::Lower>() * x;
    const double target = kReuseTolerance * rhs.norm();
    if (r.norm() <= target) return true;
    Eigen::VectorXd z = factor.solve(r), p = z;
    double rz = r.dot(z);
    for (int i = 0; i < kReuseIterations; ++i) {
      const Eigen::VectorXd hp = h.selfadjointView<Eigen::Lower>() * p;
      const double curvature = p.dot(hp);
      if (!(curvature > 0.0)) return false;
      const double alpha = rz / curvature;
      x += alpha * p;
      r -= alpha * hp;
      if (r.norm() <= target) return x.allFinite();
      z = factor.solve(r);
      const double next = r.dot(z);
      p = z + (next / rz) * p;
      rz = next;
    }
    return false;
  }
  // A Newton direction need not be exact (the line search and the
  // residual f_p - K p decide where the steps end), and from step to step H
  // changes little, so an earlier factor preconditions it well: a few
  // triangular solves instead of a new factorization, which at thousands of
  // control vertices costs ten times a whole force evaluation.
  // The relative residual 1e-3 is the loosest that keeps the tuning clouds'
  // max errors within 5 % of a near-exact solve's (1e-6); a looser one
  // raises them, a tighter one takes more iterations.
  static constexpr double kReuseTolerance = 1e-3;
  static constexpr int kReuseIterations = 20;

  Impl(const LimitSurface& surface, const SymmetricMatrix& k) : tangent(surface) { tangent.reset(k); }
};

StaticSolver::StaticSolver(const LimitSurface& surface, const SymmetricMatrix& stiffness,
                           const std::vector<int>& fixed)
    : impl_(std::make_unique<Impl>(surface, stiffness)) {
  Impl& s = *impl_;
  const int n = surface.controlVertexCount();
  if (stiffness.rows() != n || stiffness.cols() != n) throw Error("internal: stiffness has the wrong size");
  s.fixed.assign(n, false);
  for (int v : fixed) {
    if (v < 0 || v >= n) throw Error("fixed control vertex " + std::to_string(v) + " does not exist");
    s.fixed[v] = true;
  }
  if (std::find(s.fixed.begin(), s.fixed.end(), false) == s.fixed.end()) {
    throw Error("every control vertex is fixed: nothing can move");
  }
}

StaticSolver::~StaticSolver() = default;

int StaticSolver::regularizations() const { return impl_->regularizations; }

MatrixX3 StaticSolver::direction(const std::vector<ForceModel*>& forces, const MatrixX3& controlPoints,
                                 const MatrixX3& residual, bool isotropic) {
  Impl& s = *impl_;
  s.tangent.resetToLast();
  for (ForceModel* f : forces) {
    if (isotropic) {
      f->ForceModel::addTangentStiffness(controlPoints, s.tangent);
    } else {
      f->addTangentStiffness(controlPoints, s.tangent);
    }
  }
  SymmetricMatrix& h = s.tangent.matrix();
  const int dofs = static_cast<int>(h.rows());
  // Fixed vertices: their rows and columns become the identity, their right-hand side 0.
  const bool anyFixed = std::find(s.fixed.begin(), s.fixed.end(), true) != s.fixed.end();
  if (anyFixed) {
    for (int j = 0; j < dofs; ++j) {
      for (SymmetricMatrix::InnerIterator it(h, j); it; ++it) {
        if (s.fixed[it.row() / 3] || s.fixed[j / 3]) it.valueRef() = it.row() == j ? 1.0 : 0.0;
      }
    }
  }
  Eigen::VectorXd rhs(dofs);
  for (int v = 0; v < static_cast<int>(s.fixed.size()); ++v) {
    for (int a = 0; a < 3; ++a) rhs(3 * v + a) = s.fixed[v] ? 0.0 : residual(v, a);
  }
  Eigen::VectorXd solution;
  if (s.factored && !isotropic) {
    if (s.skip > 0) {
      --s.skip;
    } else if (s.solveWithEarlierFactor(h, rhs, solution)) {
      s.backoff = 1;
      return toPoints(solution, s.fixed.size());
    } else {
      s.skip = s.backoff;
      s.backoff = std::min(2 * s.backoff, 16);
    }
  }
  if (!s.analysed) {
    s.factor.analyzePattern(h);
    s.analysed = true;
  }
  const Eigen::VectorXd diagonal = h.diagonal();
  const double meanDiagonal = diagonal.cwiseAbs().mean();
  double shift = 0.0;
  for (int attempt = 0;; ++attempt) {
    if (s.factor.factorize(h)) break;
    // K alone leaves translations free; forces that pin too little (a
    // single spring, a field with no slope) leave H singular. A small shift
    // turns the step into a slightly damped one instead of failing.
    if (attempt == 3 || !(meanDiagonal > 0.0)) {
      throw Error("the equilibrium system is not positive definite even after a diagonal shift of " +
                  std::to_string(shift) + " (is the surface anchored by its forces?)");
    }
    const double next = (shift == 0.0 ? 1e-8 : 1e3 * shift / meanDiagonal) * meanDiagonal;
    for (int d = 0; d < dofs; ++d) h.coeffRef(d, d) += next - shift;
    shift = next;
    ++s.regularizations;
  }
  // The isotropic fallback's factor would precondition the next Newton step badly.
  s.factored = !isotropic;
  solution = s.factor.solve(rhs);
  return toPoints(solution, s.fixed.size());
}

}  // namespace dynsub
