#include "dynsub/TangentStiffness.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>

#include "dynsub/Error.h"
#include "dynsub/ParallelFor.h"

namespace dynsub {

struct TangentStiffness::Impl {
  const LimitSurface* surface = nullptr;
  int vertices = 0;
  // The scalar pattern's lower triangle (N by N, column-major, rows sorted,
  // the diagonal first): every pair i >= j of control vertices sharing an
  // element.
  std::vector<int> scalarOuter, scalarInner;
  // Per element, for columns c of the element (sorted, so c[i] >= c[j] for
  // i >= j): the index into matrix's values of (3 c[i], 3 c[j]) for i >= j,
  // at [j * m + i]. In a block below the diagonal (i > j), entry
  // (3 c[i] + a, 3 c[j] + b) is a entries further and, for b = 1 and 2,
  // firstStride[c[j]] and then secondStride[c[j]] more; in a diagonal block
  // (i = j) each column also starts one row lower (valueIndex).
  std::vector<std::vector<int>> entry;
  std::vector<int> firstStride, secondStride;
  // addPoints' two threads take the columns below and from this one: where
  // the elements' blocks (i >= j, one per pair, counted in column j) are
  // split in half.
  // An element's smallest columns own most of its pairs (column c[j] of
  // m has m - j), so halving the columns by number would give the first
  // thread most of the sums.
  int splitColumn = 0;
  SymmetricMatrix matrix;  // 3N by 3N, the lower triangle of the expanded pattern
  // matrix's values right after the last reset(): resetToLast() copies them
  // instead of looking up every entry of K again (a binary search each).
  std::vector<double> base;
  // Points added since the last matrix(), in the order added.
  std::vector<ElementPoint> points;
  std::vector<Eigen::Matrix3d> blocks;
  std::vector<const Eigen::RowVectorXd*> given;  // the callers' position stencils, or null
  // Scratch of addPoints(), kept from step to step: the points' order by
  // element, where each element's points start in it, their position
  // weights (a row of the element's width each, in that order) and the
  // elements with points, in increasing order.
  std::vector<int> order, start, weightStart;
  std::vector<double> weights;
  std::vector<int> touched;

  // Index into matrix.valuePtr() of (3 i + a, 3 j + b), k the position of
  // i in scalar column j; i == j (k = scalarOuter[j]) needs a >= b.
  // Column 3 j + b holds the diagonal block's rows 3 j + b .. 3 j + 2, then
  // three rows for each i > j.
  int valueIndex(int j, int k, int a, int b) const {
    const int start = matrix.outerIndexPtr()[3 * j + b];
    if (k == scalarOuter[j]) return start + a - b;
    return start + (3 - b) + 3 * (k - scalarOuter[j] - 1) + a;
  }
  int find(int i, int j) const {
    const auto begin = scalarInner.begin() + scalarOuter[j], end = scalarInner.begin() + scalarOuter[j + 1];
    const auto it = std::lower_bound(begin, end, i);
    if (it == end || *it != i) {
      throw Error("internal: control vertices " + std::to_string(i) + " and " + std::to_string(j) +
                  " share no element");
    }
    return static_cast<int>(it - scalarInner.begin());
  }
  // Adds v to (3 i + a, 3 j + a), a = 0, 1, 2, where i >= j (the lower triangle).
  void addScalarEntry(int i, int j, double v) {
    const int k = find(i, j);
    double* values = matrix.valuePtr();
    for (int a = 0; a < 3; ++a) values[valueIndex(j, k, a, a)] += v;
  }

  // Adds each point's (w w^T) (x) B into the matrix's lower triangle, w its
  // position weights on its element's columns and B its block.
  // The sum for a block (c[i], c[j]) of an element is made over the
  // element's points and added in at once, element after element in
  // increasing order. The columns are split in two halves, on two threads
  // when there are enough elements, so each value is summed by one thread
  // in one order whatever the thread count. Summing straight into the
  // matrix, instead of into per-element m x m sums first, spares zeroing,
  // filling and reading six such sums per element at every step, where
  // elements hold only a point or two each.
  void addPoints() {
    touched.clear();
    if (points.empty()) return;
    const int elements = surface->elementCount();
    start.assign(elements + 1, 0);
    for (const ElementPoint& q : points) ++start[q.element + 1];
    for (int e = 0; e < elements; ++e) start[e + 1] += start[e];
    order.resize(points.size());
    std::vector<int> next(start.begin(), start.end() - 1);
    for (size_t i = 0; i < points.size(); ++i) order[next[points[i].element]++] = static_cast<int>(i);
    weightStart.assign(elements + 1, 0);
    for (int e = 0; e < elements; ++e) {
      const int count = start[e + 1] - start[e];
      if (count > 0) touched.push_back(e);
      weightStart[e + 1] = weightStart[e] + count * static_cast<int>(surface->elementColumns(e).size());
    }
    weights.resize(static_cast<size_t>(weightStart[elements]));
    parallelFor(static_cast<Eigen::Index>(touched.size()), threadsWorth(static_cast<Eigen::Index>(points.size())),
                [&](Eigen::Index t) {
                  const int e = touched[t];
                  const int m = static_cast<int>(surface->elementColumns(e).size());
                  for (int r = start[e]; r < start[e + 1]; ++r) {
                    Eigen::Map<Eigen::RowVectorXd> row(weights.data() + weightStart[e] + (r - start[e]) * m, m);
                    const Eigen::RowVectorXd* stencil = given[order[r]];
                    if (stencil) {
                      row = *stencil;
                    } else {
                      row = surface->positionStencil(points[order[r]]);
                    }
                  }
                });
    double* values = matrix.valuePtr();
    constexpr int parts = 2;
    const auto addColumns = [&](Eigen::Index part) {
      const int firstColumn = part == 0 ? 0 : splitColumn;
      const int lastColumn = part == 0 ? splitColumn : vertices;
      for (int e : touched) {
        const std::vector<int>& columns = surface->elementColumns(e);
        const int m = static_cast<int>(columns.size());
        const double* w = weights.data() + weightStart[e];
        for (int j = 0; j < m; ++j) {
          if (columns[j] < firstColumn || columns[j] >= lastColumn) continue;
          const int stride1 = firstStride[columns[j]], stride2 = secondStride[columns[j]];
          for (int i = j; i < m; ++i) {
            // B's (0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2) summed with w_i w_j over the points.
            double sum[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
            for (int r = start[e]; r < start[e + 1]; ++r) {
              const double* row = w + (r - start[e]) * m;
              const double product = row[i] * row[j];
              const Eigen::Matrix3d& b = blocks[order[r]];
              sum[0] += product * b(0, 0), sum[1] += product * b(1, 0), sum[2] += product * b(2, 0);
              sum[3] += product * b(1, 1), sum[4] += product * b(2, 1), sum[5] += product * b(2, 2);
            }
            double* x = values + entry[e][j * m + i];
            if (i == j) {  // the diagonal block's lower triangle, column after column
              x[0] += sum[0], x[1] += sum[1], x[2] += sum[2];
              x += stride1 + 1;
              x[0] += sum[3], x[1] += sum[4];
              x += stride2 + 1;
              x[0] += sum[5];
            } else {
              x[0] += sum[0], x[1] += sum[1], x[2] += sum[2];
              x += stride1;
              x[0] += sum[1], x[1] += sum[3], x[2] += sum[4];
              x += stride2;
              x[0] += sum[2], x[1] += sum[4], x[2] += sum[5];
            }
          }
        }
      }
    };
    parallelFor(parts, touched.size() >= 64 ? parts : 1, addColumns);
    points.clear();
    blocks.clear();
    given.clear();
  }
};

TangentStiffness::TangentStiffness(const LimitSurface& surface) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.surface = &surface;
  s.vertices = surface.controlVertexCount();
  const int n = s.vertices;
  // Only the lower triangle is stored: the factorization and the
  // conjugate gradients read no other, and the points' sums are added into
  // half as many values.
  const SymmetricMatrix pattern = SymmetricMatrix(elementPattern(surface).triangularView<Eigen::Lower>());
  s.scalarOuter.assign(pattern.outerIndexPtr(), pattern.outerIndexPtr() + n + 1);
  s.scalarInner.assign(pattern.innerIndexPtr(), pattern.innerIndexPtr() + pattern.nonZeros());
  for (int j = 0; j < n; ++j) {  // every vertex shares an element with itself: the diagonal leads each column
    if (s.scalarOuter[j] == s.scalarOuter[j + 1] || s.scalarInner[s.scalarOuter[j]] != j) {
      throw Error("internal: control vertex " + std::to_string(j) + " is in no element");
    }
  }
  // Expand: scalar entry (i, j), i > j, becomes the 3 x 3 block of rows
  // 3i..3i+2, columns 3j..3j+2; (j, j) the lower triangle of its block.
  s.matrix.resize(3 * n, 3 * n);
  s.matrix.resizeNonZeros(9 * static_cast<int>(s.scalarInner.size()) - 3 * n);
  int* outer = s.matrix.outerIndexPtr();
  int* inner = s.matrix.innerIndexPtr();
  outer[0] = 0;
  s.firstStride.resize(n);
  s.secondStride.resize(n);
  for (int j = 0; j < n; ++j) {
    const int below = s.scalarOuter[j + 1] - s.scalarOuter[j] - 1;  // scalar rows i > j
    for (int b = 0; b < 3; ++b) {
      int next = outer[3 * j + b];
      for (int a = b; a < 3; ++a) inner[next++] = 3 * j + a;
      for (int k = s.scalarOuter[j] + 1; k < s.scalarOuter[j + 1]; ++k) {
        for (int a = 0; a < 3; ++a) inner[next++] = 3 * s.scalarInner[k] + a;
      }
      outer[3 * j + b + 1] = next;
    }
    // From (3 i + a, 3 j) to (3 i + a, 3 j + 1): the rest of column 3 j, less
    // the one diagonal row column 3 j + 1 lacks; likewise to 3 j + 2.
    s.firstStride[j] = 3 * below + 2;
    s.secondStride[j] = 3 * below + 1;
  }
  std::fill(s.matrix.valuePtr(), s.matrix.valuePtr() + s.matrix.nonZeros(), 0.0);
  std::vector<long long> blocksInColumn(n, 0);
  s.entry.resize(surface.elementCount());
  for (int e = 0; e < surface.elementCount(); ++e) {
    const std::vector<int>& columns = surface.elementColumns(e);
    const int m = static_cast<int>(columns.size());
    s.entry[e].assign(static_cast<size_t>(m) * m, -1);
    for (int j = 0; j < m; ++j) {
      for (int i = j; i < m; ++i) {
        s.entry[e][j * m + i] = s.valueIndex(columns[j], s.find(columns[i], columns[j]), 0, 0);
      }
      blocksInColumn[columns[j]] += m - j;
    }
  }
  const long long blocks = std::accumulate(blocksInColumn.begin(), blocksInColumn.end(), 0LL);
  for (long long below = 0; s.splitColumn < n && 2 * below < blocks; ++s.splitColumn)
    below += blocksInColumn[s.splitColumn];
}

TangentStiffness::~TangentStiffness() = default;

void TangentStiffness::reset(const SymmetricMatrix& scalar) {
  Impl& s = *impl_;
  if (scalar.rows() != s.vertices || scalar.cols() != s.vertices) throw Error("internal: stiffness has the wrong size");
  s.points.clear();
  s.blocks.clear();
  s.given.clear();
  std::fill(s.matrix.valuePtr(), s.matrix.valuePtr() + s.matrix.nonZeros(), 0.0);
  for (int j = 0; j < scalar.outerSize(); ++j) {
    for (SymmetricMatrix::InnerIterator it(scalar, j); it; ++it) {
      if (it.row() >= j) s.addScalarEntry(static_cast<int>(it.row()), j, it.value());
    }
  }
  s.base.assign(s.matrix.valuePtr(), s.matrix.valuePtr() + s.matrix.nonZeros());
}

void TangentStiffness::resetToLast() {
  Impl& s = *impl_;
  if (s.base.empty()) throw Error("internal: TangentStiffness::resetToLast before any reset");
  s.points.clear();
  s.blocks.clear();
  s.given.clear();
  std::copy(s.base.begin(), s.base.end(), s.matrix.valuePtr());
}

void TangentStiffness::addScalar(const SparseMatrix& scalar) {
  Impl& s = *impl_;
  if (scalar.rows() != s.vertices || scalar.cols() != s.vertices) throw Error("internal: stiffness has the wrong size");
  for (int i = 0; i < scalar.outerSize(); ++i) {
    for (SparseMatrix::InnerIterator it(scalar, i); it; ++it) {
      if (i >= it.col()) s.addScalarEntry(i, static_cast<int>(it.col()), it.value());
    }
  }
}

void TangentStiffness::addPoint(const ElementPoint& q, const Eigen::Matrix3d& block,
                                const Eigen::RowVectorXd* weights) {
  Impl& s = *impl_;
  // Checked here, on the caller's thread: the weights are taken later, on worker threads.
  if (q.element < 0 || q.element >= s.surface->elementCount() || !(q.u >= 0.0 && q.u <= 1.0) ||
      !(q.v >= 0.0 && q.v <= 1.0)) {
    throw Error("internal: stiffness point outside the surface's elements");
  }
  if (weights && weights->size() != static_cast<Eigen::Index>(s.surface->elementColumns(q.element).size()))
    throw Error("internal: a stiffness point's stencil has the wrong size");
  s.points.push_back(q);
  s.blocks.push_back(block);
  s.given.push_back(weights);
}

SymmetricMatrix& TangentStiffness::matrix() {
  impl_->addPoints();
  return impl_->matrix;
}

}  // namespace dynsub
