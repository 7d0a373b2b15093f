#pragma once
// Applying a sparse operator over control vertices to points.
#include <algorithm>
#include <stdexcept>

#include "dynsub/Types.h"

namespace dynsub {

// op * points in one pass over the operator, all three coordinates at once.
// Eigen 3.4 multiplies a sparse matrix by an N x 3 matrix one column at a
// time, three passes over the operator: this was measured 3 times as fast
// (2.2 ms against 6.9 ms for 98 304 rows of 16), with the same sums in the
// same order, so the same results to the bit.
// Into `result`, resized only if its size differs (a loop can reuse it).
inline void applyOperator(const SparseMatrix& op, const MatrixX3& points, MatrixX3& result) {
  eigen_assert(op.cols() == points.rows());
  result.resize(op.rows(), 3);
  const int* outer = op.outerIndexPtr();
  const int* counts = op.innerNonZeroPtr();  // null when compressed
  const int* inner = op.innerIndexPtr();
  const double* weight = op.valuePtr();
  const double* x = points.data();
  const double* y = x + points.rows();
  const double* z = y + points.rows();
  for (Eigen::Index row = 0; row < op.rows(); ++row) {
    double sx = 0.0, sy = 0.0, sz = 0.0;
    const int end = counts ? outer[row] + counts[row] : outer[row + 1];
    for (int k = outer[row]; k < end; ++k) {
      sx += weight[k] * x[inner[k]];
      sy += weight[k] * y[inner[k]];
      sz += weight[k] * z[inner[k]];
    }
    result(row, 0) = sx;
    result(row, 1) = sy;
    result(row, 2) = sz;
  }
}

// a * points, b * points and c * points for three compressed operators of one
// sparsity pattern (LimitOperators' J, J_u and J_v): the pattern and each
// control point are read once for all three, where three applyOperator()
// calls read them three times. The same sums in the same order as those.
// Throws std::invalid_argument where the operators' row extents differ; that
// their columns agree too is checked in debug builds only (reading the
// pattern three times to check it would cost what sharing it saves).
inline void applyOperators(const SparseMatrix& a, const SparseMatrix& b, const SparseMatrix& c,
                           const MatrixX3& points, MatrixX3& ra, MatrixX3& rb, MatrixX3& rc) {
  const Eigen::Index rows = a.rows();
  for (const SparseMatrix* op : {&a, &b, &c}) {
    if (!op->isCompressed() || op->rows() != rows || op->cols() != points.rows() ||
        op->nonZeros() != a.nonZeros() ||
        !std::equal(a.outerIndexPtr(), a.outerIndexPtr() + rows + 1, op->outerIndexPtr()))
      throw std::invalid_argument("applyOperators: the operators do not share one compressed pattern");
    eigen_assert(std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), op->innerIndexPtr()));
  }
  ra.resize(rows, 3);
  rb.resize(rows, 3);
  rc.resize(rows, 3);
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double *wa = a.valuePtr(), *wb = b.valuePtr(), *wc = c.valuePtr();
  const double* x = points.data();
  const double* y = x + points.rows();
  const double* z = y + points.rows();
  for (Eigen::Index row = 0; row < rows; ++row) {
    double ax = 0.0, ay = 0.0, az = 0.0, bx = 0.0, by = 0.0, bz = 0.0, cx = 0.0, cy = 0.0, cz = 0.0;
    for (int k = outer[row]; k < outer[row + 1]; ++k) {
      const double px = x[inner[k]], py = y[inner[k]], pz = z[inner[k]];
      ax += wa[k] * px;
      ay += wa[k] * py;
      az += wa[k] * pz;
      bx += wb[k] * px;
      by += wb[k] * py;
      bz += wb[k] * pz;
      cx += wc[k] * px;
      cy += wc[k] * py;
      cz += wc[k] * pz;
    }
    ra(row, 0) = ax, ra(row, 1) = ay, ra(row, 2) = az;
    rb(row, 0) = bx, rb(row, 1) = by, rb(row, 2) = bz;
    rc(row, 0) = cx, rc(row, 1) = cy, rc(row, 2) = cz;
  }
}

namespace detail {

// For each outer vector o of `op`'s storage (a column of a column-major
// matrix, a row of a row-major one), in order: each of its entries (inner
// index i, weight w) adds w * input.row(o) to result.row(i), x, y and z in
// one pass. Column-major, this is op * input; row-major, op^T * input.
template <int Options>
void scatterAdd(const Eigen::SparseMatrix<double, Options>& op, const MatrixX3& input, MatrixX3& result) {
  const int* outer = op.outerIndexPtr();
  const int* counts = op.innerNonZeroPtr();  // null when compressed
  const int* inner = op.innerIndexPtr();
  const double* weight = op.valuePtr();
  double* x = result.data();
  double* y = x + result.rows();
  double* z = y + result.rows();
  for (Eigen::Index o = 0; o < op.outerSize(); ++o) {
    const double px = input(o, 0), py = input(o, 1), pz = input(o, 2);
    const int end = counts ? outer[o] + counts[o] : outer[o + 1];
    for (int k = outer[o]; k < end; ++k) {
      x[inner[k]] += weight[k] * px;
      y[inner[k]] += weight[k] * py;
      z[inner[k]] += weight[k] * pz;
    }
  }
}

}  // namespace detail

// op * points for a column-major operator (the physical matrices), in one
// pass over it, all three coordinates at once. The same sums in the same
// order as Eigen's op * points, which makes three passes, one per column.
// The energy's x^T K x and v^T M v at every time step were a twentieth
// of a segmentation, most of it Eigen's three scattering passes.
inline MatrixX3 applyOperator(const Eigen::SparseMatrix<double, Eigen::ColMajor>& op, const MatrixX3& points) {
  eigen_assert(op.cols() == points.rows());
  MatrixX3 result = MatrixX3::Zero(op.rows(), 3);
  detail::scatterAdd(op, points, result);
  return result;
}

// op^T * values (values: one row per row of op) in one pass over the
// operator, all three coordinates at once: the integrals over quadrature
// points, J^T f. The same sums in the same order as Eigen's
// op.transpose() * values (each result row summed over op's rows in order),
// which makes three passes, one per column.
inline MatrixX3 applyTransposed(const SparseMatrix& op, const MatrixX3& values) {
  if (op.rows() != values.rows()) throw std::invalid_argument("applyTransposed: one row of values per row expected");
  MatrixX3 result = MatrixX3::Zero(op.cols(), 3);
  detail::scatterAdd(op, values, result);
  return result;
}

inline MatrixX3 applyOperator(const SparseMatrix& op, const MatrixX3& points) {
  MatrixX3 result;
  applyOperator(op, points, result);
  return result;
}

}  // namespace dynsub
