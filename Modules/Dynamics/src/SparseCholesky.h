#pragma once
// The sparse Cholesky factorization behind the implicit steps and the static
// scheme's Newton directions: CHOLMOD's supernodal LLᵀ (SuiteSparse), which
// factors dense-ish blocks with BLAS. On the kitten's equilibrium system (2316
// unknowns, 22 % of the lower triangle non-zero: its elements depend on up to
// 44 control vertices) it factors in 41 ms where Eigen's simplicial LDLᵀ took
// 245 ms (Documentation/Performance.md). Private to the Dynamics module: no
// public header brings in cholmod.h.
#include <mutex>

#include <Eigen/CholmodSupport>

#include "dynsub/PhysicalMatrices.h"

namespace dynsub {

class SparseCholesky {
 public:
  SparseCholesky() { factor_.cholmod().print = 0; }  // failures are reported by factorize()

  // The pattern of `lower` (its lower triangle is read); once per pattern.
  void analyzePattern(const SymmetricMatrix& lower) { factor_.analyzePattern(lower); }

  // True when `lower` factored as positive definite and not near-singular:
  // the smallest pivot (the square of L's smallest diagonal entry) above
  // 1e-12 of the largest, the test the simplicial LDLᵀ's D had.
  bool factorize(const SymmetricMatrix& lower) {
    const std::lock_guard<std::mutex> lock(blas());
    factor_.factorize(lower);
    return factor_.info() == Eigen::Success && factor_.reciprocalCondition() > 1e-12;
  }

  // One or more right-hand sides (columns).
  template <typename Rhs>
  typename Rhs::PlainObject solve(const Eigen::MatrixBase<Rhs>& rhs) const {
    const std::lock_guard<std::mutex> lock(blas());
    return factor_.solve(rhs);
  }

 private:
  // NB: one factorization or solve at a time in the process. CHOLMOD is
  // thread-safe, but the BLAS under it need not be: Debian's serial OpenBLAS
  // fails when two threads call it at once (`dynsub evaluate --jobs 2` runs
  // two segmentations in threads, and their steps diverged).
  static std::mutex& blas() {
    static std::mutex m;
    return m;
  }
  // CHOLMOD's estimate of the reciprocal condition, (min / max of L's diagonal)²,
  // reached through the factor Eigen keeps.
  struct Factor : Eigen::CholmodSupernodalLLT<SymmetricMatrix, Eigen::Lower> {
    double reciprocalCondition() { return cholmod_rcond(m_cholmodFactor, &cholmod()); }
  };
  Factor factor_;
};

}  // namespace dynsub
