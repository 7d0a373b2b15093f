#pragma once
// The sparse Cholesky factorization behind the implicit steps and the static
// scheme's Newton directions: CHOLMOD's supernodal LLᵀ (SuiteSparse), which
// factors dense-ish blocks with BLAS. The systems here are far from sparse
// (an element depends on up to 44 control vertices, so a fifth of the lower
// triangle can be non-zero), which is where a supernodal factor beats a
// simplicial one several times over. Private to the Dynamics module: no
// public header brings in cholmod.h.
#include <mutex>

#include <Eigen/CholmodSupport>
#include <omp.h>

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
    // about a quarter smaller, its factorization half the flops and each
    // solve faster.
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
  // 1e-12 of the largest.
  bool factorize(const SymmetricMatrix& lower) {
    const std::lock_guard<std::mutex> lock(blas());
    withoutOpenMpThreads();
    factor_.factorize(lower);
    factored_ = factor_.info() == Eigen::Success;
    return factored_ && factor_.reciprocalCondition() > 1e-12;
  }

  // One or more right-hand sides (columns) in the matrix's order, by
  // CHOLMOD's own supernodal solve on the kept factor.
  template <typename Rhs>
  typename Rhs::PlainObject solve(const Eigen::MatrixBase<Rhs>& rhs) const {
    if (!factored_) throw Error("internal: solve without a factor");
    if (rhs.rows() != factor_.rows()) throw Error("internal: a right-hand side of the wrong size");
    const std::lock_guard<std::mutex> lock(blas());
    withoutOpenMpThreads();
    typename Rhs::PlainObject x = factor_.solve(rhs.derived());
    return x;
  }

 private:
  // Debian's CHOLMOD opens OpenMP parallel regions of up to four threads
  // for small loops of its supernodal factorization. On two cores each one
  // wakes libgomp's threads and waits for them through the kernel, which
  // costs more than the loops themselves. OpenMP's max-active-levels 0 makes
  // every region inactive on this thread (the setting is per thread, and
  // factorizations run on several); DynSub itself uses no OpenMP.
  static void withoutOpenMpThreads() { omp_set_max_active_levels(0); }

  // One factorization or solve at a time in the process. CHOLMOD is
  // thread-safe, but the BLAS under it need not be: Debian's serial OpenBLAS
  // fails when two threads call it at once (`dynsub evaluate --jobs 2` runs
  // two segmentations in threads).
  static std::mutex& blas() {
    static std::mutex m;
    return m;
  }
  // CHOLMOD's estimate of the reciprocal condition, (min / max of L's
  // diagonal)², of the factor Eigen keeps.
  struct Factor : Eigen::CholmodSupernodalLLT<SymmetricMatrix, Eigen::Lower> {
    double reciprocalCondition() { return cholmod_rcond(m_cholmodFactor, &cholmod()); }
  };
  Factor factor_;
  bool factored_ = false;
};

}  // namespace dynsub
