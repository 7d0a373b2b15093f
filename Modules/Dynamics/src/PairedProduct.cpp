#include "PairedProduct.h"

#include <algorithm>

#include "dynsub/ParallelFor.h"
#include "dynsub/Error.h"

namespace dynsub {

PairedProduct::PairedProduct(const SymmetricMatrix& c, const SymmetricMatrix& p) {
  const Eigen::Index n = c.rows();
  if (c.cols() != n || p.rows() != n || p.cols() != n) throw Error("internal: paired product of unequal sizes");
  // Both on the union of the two patterns and the diagonal (explicit zeros are
  // kept), so they share one and every column has its diagonal entry.
  SymmetricMatrix diagonal(n, n);
  diagonal.setIdentity();
  SymmetricMatrix onC = c + 0.0 * p + 0.0 * diagonal;
  SymmetricMatrix onP = p + 0.0 * c + 0.0 * diagonal;
  onC.makeCompressed();
  onP.makeCompressed();
  if (onC.nonZeros() != onP.nonZeros() ||
      !std::equal(onC.innerIndexPtr(), onC.innerIndexPtr() + onC.nonZeros(), onP.innerIndexPtr())) {
    throw Error("internal: the paired product's matrices do not share a pattern");
  }
  start_.assign(1, 0);
  for (Eigen::Index j = 0; j < n; ++j) {
    for (int k = onC.outerIndexPtr()[j]; k < onC.outerIndexPtr()[j + 1]; ++k) {
      const int i = onC.innerIndexPtr()[k];
      if (i < j) continue;  // rows are sorted: the diagonal comes first
      row_.push_back(i);
      weights_.push_back(onC.valuePtr()[k]);
      weights_.push_back(onP.valuePtr()[k]);
    }
    start_.push_back(static_cast<int>(row_.size()));
  }
  p_.assign(4 * n, 0.0);
  q_.assign(4 * n, 0.0);
  sums_.assign(4 * n, 0.0);
  // Two halves of the entries for two threads, where each half is worth one.
  const long entries = static_cast<long>(row_.size());
  if (entries >= 2 * kThreadShare) {
    while (start_[split_] < entries / 2) ++split_;
    secondSums_.assign(4 * n, 0.0);
  }
}

namespace {

// sums = C p + P q, points as [x y z 0]. Two partial sums per column (even and
// odd entries), so that each addition need not wait for the one before.
DYNSUB_KERNEL void product(int n, int begin, int end, const int* start, const int* row, const double* weights,
                           const double* p, const double* q, double* sums) {
  std::fill(sums, sums + 4 * n, 0.0);
  for (int j = begin; j < end; ++j) {
    Lanes pj, qj;
    load(pj, p + 4 * j);
    load(qj, q + 4 * j);
    const double* w = weights + 2 * start[j];
    Lanes even = w[0] * pj + w[1] * qj, odd = {};
    int k = start[j] + 1;
    const int last = start[j + 1];
    for (; k + 2 <= last; k += 2) {
      const int i0 = row[k], i1 = row[k + 1];
      const double a0 = weights[2 * k], b0 = weights[2 * k + 1];
      const double a1 = weights[2 * k + 2], b1 = weights[2 * k + 3];
      Lanes p0, q0, p1, q1, s0, s1;
      load(p0, p + 4 * i0), load(q0, q + 4 * i0), load(s0, sums + 4 * i0);
      load(p1, p + 4 * i1), load(q1, q + 4 * i1), load(s1, sums + 4 * i1);
      even += a0 * p0 + b0 * q0;
      odd += a1 * p1 + b1 * q1;
      store(sums + 4 * i0, s0 + (a0 * pj + b0 * qj));
      store(sums + 4 * i1, s1 + (a1 * pj + b1 * qj));
    }
    if (k < last) {
      const int i = row[k];
      const double a = weights[2 * k], b = weights[2 * k + 1];
      Lanes pi, qi, si;
      load(pi, p + 4 * i), load(qi, q + 4 * i), load(si, sums + 4 * i);
      even += a * pi + b * qi;
      store(sums + 4 * i, si + (a * pj + b * qj));
    }
    Lanes sj;
    load(sj, sums + 4 * j);
    store(sums + 4 * j, sj + (even + odd));
  }
}

void productBaseline(int n, int begin, int end, const int* start, const int* row, const double* weights,
                     const double* p, const double* q, double* sums) {
  product(n, begin, end, start, row, weights, p, q, sums);
}

DYNSUB_AVX2 void productAvx2(int n, int begin, int end, const int* start, const int* row, const double* weights,
                             const double* p, const double* q, double* sums) {
  product(n, begin, end, start, row, weights, p, q, sums);
}

}  // namespace

void PairedProduct::sum(const MatrixX3& p, const MatrixX3& q) {
  const int n = static_cast<int>(p_.size() / 4);
  if (p.rows() != n || q.rows() != n) throw Error("internal: paired product of unequal sizes");
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      p_[4 * i + a] = p(i, a);
      q_[4 * i + a] = q(i, a);
    }
  }
  auto columns = [&](int begin, int end, std::vector<double>& sums) {
    if (hasAvx2Fma()) {
      productAvx2(n, begin, end, start_.data(), row_.data(), weights_.data(), p_.data(), q_.data(), sums.data());
    } else {
      productBaseline(n, begin, end, start_.data(), row_.data(), weights_.data(), p_.data(), q_.data(), sums.data());
    }
  };
  if (split_ == 0) {
    columns(0, n, sums_);
    return;
  }
  // The columns from split_ on are summed apart (on a second thread where
  // there is a second core, ParallelFor.h) and added last, the same order either way.
  bothAtOnce([&] { columns(0, split_, sums_); }, [&] { columns(split_, n, secondSums_); });
  for (size_t i = 0; i < sums_.size(); ++i) sums_[i] += secondSums_[i];
}

void PairedProduct::apply(double w, const MatrixX3& f, const MatrixX3& p, const MatrixX3& q, MatrixX3& rhs) {
  const int n = static_cast<int>(p_.size() / 4);
  if (f.rows() != n) throw Error("internal: paired product of unequal sizes");
  sum(p, q);
  rhs.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) rhs(i, a) = w * f(i, a) + sums_[4 * i + a];
  }
}

}  // namespace dynsub
