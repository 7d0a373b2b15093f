#pragma once
// Implicit time integration of M p'' + D p' + K p = f_p (TVCG 1998 §3.3).
//   second order (eq. 31): (2M + D dt + 2 dt^2 K) p(t+dt)
//                              = 2 dt^2 f_p + (D dt - 2M) p(t-dt) + 4 M p(t)
//   first order, massless (eq. 32): (D + 2 dt K) p(t+dt) = 2 dt f_p + D p(t-dt)
// The left-hand matrix is constant while the control-mesh topology is: it is
// factored (or preconditioned) once and reused every step.
//
// Stabilized explicit forces. The papers evaluate f_p at t + dt. Forces here
// are evaluated at the current state, which is unstable for stiff springs (for
// eq. 32 whenever a spring is stiffer than the surface in some mode, at any
// dt). So a stiffness S of the forces (for springs sum k J^T J at the
// attachments when the integrator was built; for a force field, the bound of
// its slope integrated as sum w |s_u x s_v| J^T J) is moved to the left side:
// K is replaced by K + S and S p(t) is added to f_p. At an equilibrium the two
// S terms cancel, so equilibria are those of the papers' equations; only the
// path to them is damped. An empty S gives the papers' schemes unchanged.
//
// Solvers: sparse Cholesky (CHOLMOD's supernodal LL^T, factored once and
// solved by CHOLMOD; the right-hand side on two threads for large systems,
// with the same results as one), conjugate
// gradients (the papers' solver) and conjugate gradients with an incomplete
// Cholesky preconditioner (the speed-up TVCG §5 asks for), both warm-started
// from p(t). Fixed control vertices keep their positions.
#include <memory>
#include <vector>

#include "dynsub/PhysicalMatrices.h"

namespace dynsub {

// Static is not a time integration: it solves for the equilibrium directly
// (StaticSolver.h); Simulation.h routes it there.
enum class IntegrationScheme { SecondOrder, FirstOrder, Static };
enum class LinearSolver { Cholesky, ConjugateGradient, PreconditionedConjugateGradient };

const char* toString(IntegrationScheme scheme);
const char* toString(LinearSolver solver);
// Parses "second-order"/"first-order"/"static" and "cholesky"/"cg"/"pcg"; throws dynsub::Error.
IntegrationScheme parseIntegrationScheme(const std::string& text);
LinearSolver parseLinearSolver(const std::string& text);

struct IntegratorOptions {
  IntegrationScheme scheme = IntegrationScheme::FirstOrder;
  LinearSolver solver = LinearSolver::Cholesky;
  double timeStep = 0.5;           // s
  double solverTolerance = 1e-10;  // relative residual of the iterative solvers
  int solverMaxIterations = 5000;
};

class Integrator {
 public:
  // `fixed` lists control vertices that do not move. Throws dynsub::Error for
  // a bad time step or when the left-hand matrix cannot be factored (it is
  // singular, e.g. first order with no damping and nothing anchoring a mode).
  Integrator(const PhysicalMatrices& matrices, const SymmetricMatrix& forceStiffness, const std::vector<int>& fixed,
             const IntegratorOptions& options);
  ~Integrator();
  Integrator(Integrator&&) noexcept;
  Integrator& operator=(Integrator&&) noexcept;

  // The same integrator with another force stiffness (the stabilizer's
  // update, Simulation.h) and the same matrices and fixed vertices. The
  // factorization's ordering and symbolic analysis are kept while the
  // left-hand matrix's pattern holds, so only its values are factored again.
  void restabilize(const PhysicalMatrices& matrices, const SymmetricMatrix& forceStiffness);
  // p(t + dt) from p(t - dt), p(t) and the generalized force at p(t) (all
  // #control x 3). Throws dynsub::Error when an iterative solver fails.
  MatrixX3 step(const MatrixX3& previous, const MatrixX3& current, const MatrixX3& force);
  // Iterations of the last iterative solve (summed over x, y, z); 0 for Cholesky.
  int lastIterations() const;
  const IntegratorOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynsub
