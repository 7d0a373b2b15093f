#pragma once
// The sparse Cholesky factorization behind the implicit steps and the static
// scheme's Newton directions: CHOLMOD's supernodal LLᵀ (SuiteSparse), which
// factors dense-ish blocks with BLAS. On the kitten's equilibrium system (2316
// unknowns, 22 % of the lower triangle non-zero: its elements depend on up to
// 44 control vertices) it factors in 41 ms where Eigen's simplicial LDLᵀ took
// 245 ms (Documentation/Performance.md). The solves against the factor are
// the project's own (SupernodalSolve.h). Private to the Dynamics module: no
// public header brings in cholmod.h.
#include <mutex>
#include <vector>

#include <Eigen/CholmodSupport>
#include <omp.h>

#include "SupernodalSolve.h"
#include "dynsub/Error.h"
#include "dynsub/PhysicalMatrices.h"

namespace dynsub {

class SparseCholesky {
 public:
  SparseCholesky() {
    cholmod_common& common = factor_.cholmod();
    common.print = 0;  // failures are reported by factorize()
    // The fill-reducing ordering with fewer flops of two: minimum degree (AMD)
    // and nested dissection (METIS, CHOLMOD's NESDIS). CHOLMOD's default tries
    // nested dissection only when minimum degree looks poor; on the surface
    // systems here it often pays anyway: at 6146 control vertices it makes L
    // 28 % smaller, its factorization half the flops and each solve faster.
    common.nmethods = 2;
    common.method[0].ordering = CHOLMOD_AMD;
    common.method[1].ordering = CHOLMOD_NESDIS;
  }

  // The pattern of `lower` (its lower triangle is read); once per pattern.
  void analyzePattern(const SymmetricMatrix& lower) {
    withoutOpenMpThreads();
    factor_.analyzePattern(lower);
  }

  // True when `lower` factored as positive definite and not near-singular:
  // the smallest pivot (the square of L's smallest diagonal entry) above
  // 1e-12 of the largest, the test the simplicial LDLᵀ's D had.
  bool factorize(const SymmetricMatrix& lower) {
    const std::lock_guard<std::mutex> lock(blas());
    withoutOpenMpThreads();
    factor_.factorize(lower);
    view_ = factor_.view();
    if (view_.values != nullptr) {
      inverseDiagonal_ = inverseDiagonalOf(view_);
      view_.inverseDiagonal = inverseDiagonal_.data();
      // NB: starting a thread costs about 50 us; a subtree of 200 000
      // entries takes about as long per pass with three right-hand sides.
      splitForTwoThreads(view_, 200000);
    }
    return factor_.info() == Eigen::Success && factor_.reciprocalCondition() > 1e-12;
  }

  // L's row k is row permutation()[k] of the factored matrix.
  const int* permutation() const { return view_.perm; }
  int unknowns() const { return view_.unknowns; }

  // Solves in place for `columns` right-hand sides already in L's order (see
  // permutation()), one after the other in x, each of unknowns() values.
  void solveInPermutedOrder(double* x, int columns) const {
    if (view_.values == nullptr) throw Error("internal: solve without a factor");
    std::vector<double> scratch(3 * static_cast<size_t>(largestSupernode(view_)));
    supernodalSolve(view_, x, columns, scratch.data());
  }

  // One or more right-hand sides (columns) in the matrix's order.
  template <typename Rhs>
  typename Rhs::PlainObject solve(const Eigen::MatrixBase<Rhs>& rhs) const {
    if (rhs.rows() != view_.unknowns) throw Error("internal: a right-hand side of the wrong size");
    const int n = view_.unknowns, columns = static_cast<int>(rhs.cols());
    Eigen::MatrixXd x(n, columns);
    for (int c = 0; c < columns; ++c) {
      for (int k = 0; k < n; ++k) x(k, c) = rhs(view_.perm[k], c);
    }
    solveInPermutedOrder(x.data(), columns);
    typename Rhs::PlainObject result(n, columns);
    for (int c = 0; c < columns; ++c) {
      for (int k = 0; k < n; ++k) result(view_.perm[k], c) = x(k, c);
    }
    return result;
  }

 private:
  // NB: Debian's CHOLMOD opens OpenMP parallel regions of up to four threads
  // for small loops of its supernodal factorization. On two cores each one
  // woke libgomp's threads and waited for them through the kernel: the
  // kitten's fit made 43 600 futex calls, waiting 3.1 s in all, and took
  // 3.26 s (median) against 2.92 s with the regions run by the calling thread
  // alone (the same control mesh to the byte; Documentation/Performance.md).
  // OpenMP's max-active-levels 0 makes every region inactive on this thread
  // (the setting is per thread, and factorizations run on several); DynSub
  // itself uses no OpenMP.
  static void withoutOpenMpThreads() { omp_set_max_active_levels(0); }

  // NB: one factorization at a time in the process. CHOLMOD is thread-safe,
  // but the BLAS under it need not be: Debian's serial OpenBLAS fails when
  // two threads call it at once (`dynsub evaluate --jobs 2` runs two
  // segmentations in threads, and their steps diverged). The solves use no
  // BLAS and need no lock.
  static std::mutex& blas() {
    static std::mutex m;
    return m;
  }
  // CHOLMOD's estimate of the reciprocal condition, (min / max of L's diagonal)²,
  // reached through the factor Eigen keeps.
  struct Factor : Eigen::CholmodSupernodalLLT<SymmetricMatrix, Eigen::Lower> {
    double reciprocalCondition() { return cholmod_rcond(m_cholmodFactor, &cholmod()); }
    // L's arrays as CHOLMOD keeps them, valid until the next factorization;
    // empty unless L is supernodal, real and int-indexed (it always is here).
    SupernodalFactorView view() const {
      SupernodalFactorView v;
      const cholmod_factor* L = m_cholmodFactor;
      if (L == nullptr || !L->is_super || L->xtype != CHOLMOD_REAL || L->itype != CHOLMOD_INT || L->minor < L->n)
        return v;
      v.unknowns = static_cast<int>(L->n);
      v.supernodes = static_cast<int>(L->nsuper);
      v.perm = static_cast<const int*>(L->Perm);
      v.firstColumn = static_cast<const int*>(L->super);
      v.rowStart = static_cast<const int*>(L->pi);
      v.rows = static_cast<const int*>(L->s);
      v.valueStart = static_cast<const int*>(L->px);
      v.values = static_cast<const double*>(L->x);
      return v;
    }
  };
  Factor factor_;
  SupernodalFactorView view_;
  std::vector<double> inverseDiagonal_;
};

}  // namespace dynsub
