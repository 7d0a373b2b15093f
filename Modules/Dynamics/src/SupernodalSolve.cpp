#include "SupernodalSolve.h"

#include <algorithm>
#include <vector>

#include "Lanes.h"
#include "dynsub/ParallelFor.h"

namespace dynsub {
namespace {

// One supernode's columns are solved in blocks of this many: each pass over
// the rows below a block then reads those rows' right-hand sides once for
// four columns of L, not once per column.
constexpr int kBlock = 4;

// Forward, the supernode's own rows: L11 y = x on its first nc rows,
// gathered into v (K columns, `stride` apart). Lb is the supernode's block
// (column-major, leading dimension `rows`); inverse holds 1 / L's diagonal.
template <int K>
DYNSUB_KERNEL void forwardTriangle(const double* __restrict Lb, const double* __restrict inverse, int nc, int rows,
                                   double* __restrict v, int stride) {
  for (int c = 0; c < nc; c += kBlock) {
    const int width = std::min(kBlock, nc - c);
    // The small triangle of the block's own rows.
    for (int j = 0; j < width; ++j) {
      const double* column = Lb + static_cast<long>(c + j) * rows;
      for (int k = 0; k < K; ++k) {
        double* vk = v + k * stride;
        vk[c + j] *= inverse[c + j];
        for (int i = j + 1; i < width; ++i) vk[c + i] -= column[c + i] * vk[c + j];
      }
    }
    // The own rows below the block, four columns at a time.
    const int below = c + width;
    if (width == kBlock) {
      const double* L0 = Lb + static_cast<long>(c) * rows;
      const double* L1 = L0 + rows;
      const double* L2 = L1 + rows;
      const double* L3 = L2 + rows;
      // Each row's four weights are read once for all K right-hand sides.
      double a[K][kBlock];
      for (int k = 0; k < K; ++k) {
        for (int j = 0; j < kBlock; ++j) a[k][j] = v[k * stride + c + j];
      }
      for (int r = below; r < nc; ++r) {
        const double l0 = L0[r], l1 = L1[r], l2 = L2[r], l3 = L3[r];
        for (int k = 0; k < K; ++k) v[k * stride + r] -= l0 * a[k][0] + l1 * a[k][1] + l2 * a[k][2] + l3 * a[k][3];
      }
    } else {
      for (int j = 0; j < width; ++j) {
        const double* Lj = Lb + static_cast<long>(c + j) * rows;
        for (int k = 0; k < K; ++k) {
          double* __restrict vk = v + k * stride;
          const double a = vk[c + j];
          for (int r = below; r < nc; ++r) vk[r] -= Lj[r] * a;
        }
      }
    }
  }
}

// Forward, the rows below: x[below[r]] -= sum over c of L[nc + r, c] y[c],
// eight rows at a time, each row's sum held in registers over all nc
// columns, so each right-hand side value is written once.
// Rows from `outsideFrom` on are not written in x but subtracted from
// `outside` (K columns of n - outsideFrom values): a second thread's share of
// the rows that the first thread's supernodes update too.
// (Only the second subtree's pass redirects: `Redirect` keeps the test out
// of the other passes.)
template <int K, bool Redirect>
DYNSUB_KERNEL void forwardBelow(const double* __restrict Lb, int nc, int rows, const double* __restrict v, int stride,
                                const int* __restrict below, double* __restrict x, int n, int outsideFrom,
                                double* __restrict outside) {
  auto target = [&](int k, int row) -> double& {
    if (!Redirect || row < outsideFrom) return x[k * n + row];
    return outside[k * (n - outsideFrom) + row - outsideFrom];
  };
  int r = nc;
  for (; r + 2 * kLanes <= rows; r += 2 * kLanes) {
    Lanes sums[K][2] = {};
    for (int c = 0; c < nc; ++c) {
      Lanes l0, l1;
      load(l0, Lb + static_cast<long>(c) * rows + r);
      load(l1, Lb + static_cast<long>(c) * rows + r + kLanes);
      for (int k = 0; k < K; ++k) {
        const double value = v[k * stride + c];
        const Lanes y = {value, value, value, value};
        sums[k][0] += l0 * y;
        sums[k][1] += l1 * y;
      }
    }
    for (int k = 0; k < K; ++k) {
      for (int t = 0; t < kLanes; ++t) {
        target(k, below[r - nc + t]) -= sums[k][0][t];
        target(k, below[r - nc + kLanes + t]) -= sums[k][1][t];
      }
    }
  }
  for (; r < rows; ++r) {
    double sums[K] = {};
    for (int c = 0; c < nc; ++c) {
      const double l = Lb[static_cast<long>(c) * rows + r];
      for (int k = 0; k < K; ++k) sums[k] += l * v[k * stride + c];
    }
    for (int k = 0; k < K; ++k) target(k, below[r - nc]) -= sums[k];
  }
}

// sum over r in [from, rows) of L[r] v[r], two lanes then their sum.
DYNSUB_KERNEL double dot(const double* __restrict L, const double* __restrict v, int from, int rows) {
  Lanes lanes = {};
  int r = from;
  for (; r + kLanes <= rows; r += kLanes) {
    Lanes l, x;
    load(l, L + r);
    load(x, v + r);
    lanes += l * x;
  }
  double total = sum(lanes);
  for (; r < rows; ++r) total += L[r] * v[r];
  return total;
}

// Backward: L' y = x for one supernode, on its rows gathered into v, whose
// rows below its own columns already hold their solution.
template <int K>
DYNSUB_KERNEL void backward(const double* __restrict Lb, const double* __restrict inverse, int nc, int rows,
                            double* __restrict v, int stride) {
  // Blocks from the last columns to the first; the first block takes the remainder.
  for (int end = nc; end > 0;) {
    const int width = end % kBlock == 0 ? kBlock : end % kBlock;
    const int c = end - width;
    if (width == kBlock && K == 3) {
      const double* L0 = Lb + static_cast<long>(c) * rows;
      const double* L1 = L0 + rows;
      const double* L2 = L1 + rows;
      const double* L3 = L2 + rows;
      const double* v0 = v;
      const double* v1 = v + stride;
      const double* v2 = v + 2 * stride;
      Lanes s[4][3] = {};
      int r = end;
      for (; r + kLanes <= rows; r += kLanes) {
        Lanes x, y, z, l0, l1, l2, l3;
        load(x, v0 + r), load(y, v1 + r), load(z, v2 + r);
        load(l0, L0 + r), load(l1, L1 + r), load(l2, L2 + r), load(l3, L3 + r);
        s[0][0] += l0 * x, s[0][1] += l0 * y, s[0][2] += l0 * z;
        s[1][0] += l1 * x, s[1][1] += l1 * y, s[1][2] += l1 * z;
        s[2][0] += l2 * x, s[2][1] += l2 * y, s[2][2] += l2 * z;
        s[3][0] += l3 * x, s[3][1] += l3 * y, s[3][2] += l3 * z;
      }
      const double* Lj[4] = {L0, L1, L2, L3};
      const double* vk[3] = {v0, v1, v2};
      for (int j = 0; j < 4; ++j) {
        for (int k = 0; k < 3; ++k) {
          double total = sum(s[j][k]);
          for (int t = r; t < rows; ++t) total += Lj[j][t] * vk[k][t];
          v[k * stride + c + j] -= total;
        }
      }
    } else {
      for (int j = 0; j < width; ++j) {
        const double* column = Lb + static_cast<long>(c + j) * rows;
        for (int k = 0; k < K; ++k) v[k * stride + c + j] -= dot(column, v + k * stride, end, rows);
      }
    }
    // The small triangle, transposed, last column first.
    for (int j = width - 1; j >= 0; --j) {
      const double* column = Lb + static_cast<long>(c + j) * rows;
      for (int k = 0; k < K; ++k) {
        double* vk = v + k * stride;
        double value = vk[c + j];
        for (int i = j + 1; i < width; ++i) value -= column[c + i] * vk[c + i];
        vk[c + j] = value * inverse[c + j];
      }
    }
    end = c;
  }
}

// L y = x over supernodes [begin, end), in order.
template <int K>
DYNSUB_KERNEL void forwardRange(const SupernodalFactorView& f, int begin, int end, double* x, double* v, int stride,
                                int outsideFrom, double* outside) {
  const int n = f.unknowns;
  for (int s = begin; s < end; ++s) {
    const int k0 = f.firstColumn[s], nc = f.firstColumn[s + 1] - k0;
    const int rows = f.rowStart[s + 1] - f.rowStart[s];
    const double* Lb = f.values + f.valueStart[s];
    for (int k = 0; k < K; ++k) std::copy(x + k * n + k0, x + k * n + k0 + nc, v + k * stride);
    forwardTriangle<K>(Lb, f.inverseDiagonal + k0, nc, rows, v, stride);
    for (int k = 0; k < K; ++k) std::copy(v + k * stride, v + k * stride + nc, x + k * n + k0);
    if (outside != nullptr) {
      forwardBelow<K, true>(Lb, nc, rows, v, stride, f.rows + f.rowStart[s] + nc, x, n, outsideFrom, outside);
    } else {
      forwardBelow<K, false>(Lb, nc, rows, v, stride, f.rows + f.rowStart[s] + nc, x, n, outsideFrom, outside);
    }
  }
}

// L' y = x over supernodes [begin, end), last first.
template <int K>
DYNSUB_KERNEL void backwardRange(const SupernodalFactorView& f, int begin, int end, double* x, double* v, int stride) {
  const int n = f.unknowns;
  for (int s = end - 1; s >= begin; --s) {
    const int k0 = f.firstColumn[s], nc = f.firstColumn[s + 1] - k0;
    const int rows = f.rowStart[s + 1] - f.rowStart[s];
    const int* below = f.rows + f.rowStart[s] + nc;
    for (int k = 0; k < K; ++k) {
      std::copy(x + k * n + k0, x + k * n + k0 + nc, v + k * stride);
      for (int r = nc; r < rows; ++r) v[k * stride + r] = x[k * n + below[r - nc]];
    }
    backward<K>(f.values + f.valueStart[s], f.inverseDiagonal + k0, nc, rows, v, stride);
    for (int k = 0; k < K; ++k) std::copy(v + k * stride, v + k * stride + nc, x + k * n + k0);
  }
}

template <int K>
void forwardBaseline(const SupernodalFactorView& f, int begin, int end, double* x, double* v, int stride,
                     int outsideFrom, double* outside) {
  forwardRange<K>(f, begin, end, x, v, stride, outsideFrom, outside);
}

template <int K>
DYNSUB_AVX2 void forwardAvx2(const SupernodalFactorView& f, int begin, int end, double* x, double* v, int stride,
                             int outsideFrom, double* outside) {
  forwardRange<K>(f, begin, end, x, v, stride, outsideFrom, outside);
}

template <int K>
void backwardBaseline(const SupernodalFactorView& f, int begin, int end, double* x, double* v, int stride) {
  backwardRange<K>(f, begin, end, x, v, stride);
}

template <int K>
DYNSUB_AVX2 void backwardAvx2(const SupernodalFactorView& f, int begin, int end, double* x, double* v, int stride) {
  backwardRange<K>(f, begin, end, x, v, stride);
}

template <int K>
void forward(const SupernodalFactorView& f, int begin, int end, double* x, double* v, int stride, int outsideFrom,
             double* outside) {
  if (hasAvx2Fma()) {
    forwardAvx2<K>(f, begin, end, x, v, stride, outsideFrom, outside);
  } else {
    forwardBaseline<K>(f, begin, end, x, v, stride, outsideFrom, outside);
  }
}

template <int K>
void backward(const SupernodalFactorView& f, int begin, int end, double* x, double* v, int stride) {
  if (hasAvx2Fma()) {
    backwardAvx2<K>(f, begin, end, x, v, stride);
  } else {
    backwardBaseline<K>(f, begin, end, x, v, stride);
  }
}

// K columns of x. With a split (SupernodalFactorView::middle < top), the two
// subtrees [0, middle) and [middle, top) are solved on two threads (where
// there are two cores, ParallelFor.h): in the forward pass the second one's
// updates of the rows above both (columns from firstColumn[top] on) are
// summed apart and subtracted after both, so the sums run in the same order
// whether one thread or two did them.
template <int K>
void solveColumns(const SupernodalFactorView& f, double* x, double* v, int stride) {
  const int n = f.unknowns;
  if (!(f.middle < f.top)) {
    forward<K>(f, 0, f.supernodes, x, v, stride, n, nullptr);
    backward<K>(f, 0, f.supernodes, x, v, stride);
    return;
  }
  const int above = f.firstColumn[f.top];
  std::vector<double> outside(static_cast<size_t>(K) * (n - above), 0.0);
  std::vector<double> second(static_cast<size_t>(K) * stride);
  bothAtOnce([&] { forward<K>(f, 0, f.middle, x, v, stride, n, nullptr); },
             [&] { forward<K>(f, f.middle, f.top, x, second.data(), stride, above, outside.data()); });
  for (int k = 0; k < K; ++k) {
    for (int r = above; r < n; ++r) x[k * n + r] += outside[k * (n - above) + r - above];
  }
  forward<K>(f, f.top, f.supernodes, x, v, stride, n, nullptr);
  backward<K>(f, f.top, f.supernodes, x, v, stride);
  bothAtOnce([&] { backward<K>(f, 0, f.middle, x, v, stride); },
             [&] { backward<K>(f, f.middle, f.top, x, second.data(), stride); });
}

}  // namespace

std::vector<double> inverseDiagonalOf(const SupernodalFactorView& f) {
  std::vector<double> inverse(f.unknowns);
  for (int s = 0; s < f.supernodes; ++s) {
    const int rows = f.rowStart[s + 1] - f.rowStart[s];
    const double* Lb = f.values + f.valueStart[s];
    for (int c = 0; c < f.firstColumn[s + 1] - f.firstColumn[s]; ++c) {
      inverse[f.firstColumn[s] + c] = 1.0 / Lb[static_cast<long>(c) * rows + c];
    }
  }
  return inverse;
}

int largestSupernode(const SupernodalFactorView& f) {
  int largest = 0;
  for (int s = 0; s < f.supernodes; ++s) largest = std::max(largest, f.rowStart[s + 1] - f.rowStart[s]);
  return largest;
}

void supernodalSolve(const SupernodalFactorView& f, double* x, int columns, double* scratch) {
  const int stride = largestSupernode(f);
  // Three columns (x, y and z of the implicit steps) in one pass over L; others one at a time.
  int done = 0;
  for (; done + 3 <= columns; done += 3) {
    solveColumns<3>(f, x + static_cast<long>(done) * f.unknowns, scratch, stride);
  }
  for (; done < columns; ++done) solveColumns<1>(f, x + static_cast<long>(done) * f.unknowns, scratch, stride);
}

void splitForTwoThreads(SupernodalFactorView& f, long minimumShare) {
  f.middle = f.top = 0;
  const int count = f.supernodes;
  if (count < 3) return;
  // Each supernode's parent: the supernode of its first row below its own
  // columns (none for a root). CHOLMOD numbers them in postorder, so each
  // subtree is a contiguous range ending at its root.
  std::vector<int> supernodeOfColumn(f.unknowns);
  for (int s = 0; s < count; ++s) {
    std::fill(supernodeOfColumn.begin() + f.firstColumn[s], supernodeOfColumn.begin() + f.firstColumn[s + 1], s);
  }
  std::vector<int> parent(count, count);  // count: a root, child of a virtual root
  std::vector<long> work(count + 1, 0);   // entries of L in each subtree
  for (int s = 0; s < count; ++s) {
    const int nc = f.firstColumn[s + 1] - f.firstColumn[s], rows = f.rowStart[s + 1] - f.rowStart[s];
    if (rows > nc) parent[s] = supernodeOfColumn[f.rows[f.rowStart[s] + nc]];
    if (parent[s] <= s) return;  // not in postorder: no split
    work[s] += static_cast<long>(nc) * rows;
    work[parent[s]] += work[s];
  }
  // Down from the (virtual) root while a node has one child; then split that
  // node's children, in order, where the two shares are most nearly equal.
  int node = count;
  std::vector<int> children;
  for (;;) {
    children.clear();
    for (int s = 0; s < node; ++s) {
      if (parent[s] == node) children.push_back(s);
    }
    if (children.size() != 1) break;
    node = children[0];
  }
  if (children.size() < 2) return;
  long total = 0;
  for (int c : children) total += work[c];
  long left = 0, bestBalance = -1;
  int bestMiddle = 0;
  for (size_t i = 0; i + 1 < children.size(); ++i) {
    left += work[children[i]];
    const long smaller = std::min(left, total - left);
    if (smaller > bestBalance) bestBalance = smaller, bestMiddle = children[i] + 1;
  }
  if (bestBalance < minimumShare) return;
  f.middle = bestMiddle;
  f.top = node == count ? count : node;
}

}  // namespace dynsub
