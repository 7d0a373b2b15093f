#pragma once
// Triangular solves against a supernodal Cholesky factor L (A = P' L L' P),
// private to the Dynamics module. CHOLMOD factors (SparseCholesky.h); these
// solves replace its own, which call BLAS once per supernode and right-hand
// side block: with the three coordinates' right-hand sides those calls are
// mostly overhead (a 6146-unknown step's solve, measured alone: 1.3 ms in
// CHOLMOD, 0.9 ms here on one thread; Documentation/Performance.md). They
// use no BLAS, so unlike CHOLMOD's they need no process-wide lock.
#include <vector>

namespace dynsub {

// A view of L as CHOLMOD keeps it (cholmod_factor, supernodal, int indices):
// supernode s holds columns firstColumn[s] .. firstColumn[s+1]-1 as a dense
// column-major block of rowStart[s+1]-rowStart[s] rows at values +
// valueStart[s]; its row numbers are rows[rowStart[s] ...], its own columns'
// rows first. perm[k] is the row of A at L's row k; inverseDiagonal[k] is
// 1 / L(k, k).
struct SupernodalFactorView {
  int unknowns = 0;
  int supernodes = 0;
  const int* perm = nullptr;
  const int* firstColumn = nullptr;
  const int* rowStart = nullptr;
  const int* rows = nullptr;
  const int* valueStart = nullptr;
  const double* values = nullptr;
  const double* inverseDiagonal = nullptr;
  // Supernodes [0, middle) and [middle, top) are two independent subtrees;
  // the rest lie above both. No split when middle == top (splitForTwoThreads).
  int middle = 0;
  int top = 0;
};

// Finds two subtrees of L's elimination tree that two threads can solve at
// once, each holding at least `minimumShare` entries of L; sets no split
// where there are none such. Results do not depend on the split's threads.
void splitForTwoThreads(SupernodalFactorView& factor, long minimumShare);

// 1 / L(k, k) for each column k, for SupernodalFactorView::inverseDiagonal.
std::vector<double> inverseDiagonalOf(const SupernodalFactorView& factor);

// The most rows of any supernode: supernodalSolve's scratch needs three
// times that many doubles.
int largestSupernode(const SupernodalFactorView& factor);

// Solves L L' y = x in place for `columns` right-hand sides, each a column of
// `factor.unknowns` values in L's (permuted) order, one after the other in x.
// `scratch` holds 3 * largestSupernode(factor) doubles. The sums run in
// a fixed order, so results do not vary from run to run.
void supernodalSolve(const SupernodalFactorView& factor, double* x, int columns, double* scratch);

}  // namespace dynsub
