#pragma once
// w f + C p + P q for two symmetric matrices C and P over the control
// vertices: the right-hand side of every implicit time step (Integrator.cpp).
// Private to the Dynamics module. Large products are shared by two threads,
// with the same results as one.
//
// Only the lower triangles are kept, on the union of the two patterns, each
// entry's two weights side by side: one pass over half the entries, each
// entry below the diagonal serving both its row and its column. The points
// are read as [x y z 0] groups of four, one vector operation per vertex.
#include <vector>

#include "Lanes.h"
#include "dynsub/PhysicalMatrices.h"

namespace dynsub {

class PairedProduct {
 public:
  PairedProduct() = default;
  // C and P stored whole (both triangles), of one size; their patterns may differ.
  PairedProduct(const SymmetricMatrix& c, const SymmetricMatrix& p);

  // rhs = w f + C p + P q, all #vertices x 3. Not for two threads at once
  // (it keeps its scratch).
  void apply(double w, const MatrixX3& f, const MatrixX3& p, const MatrixX3& q, MatrixX3& rhs);

 private:
  std::vector<int> start_;       // column j's entries: [start_[j], start_[j + 1]), the diagonal first
  std::vector<int> row_;         // each entry's row i >= j
  std::vector<double> weights_;  // C_ij, P_ij for each entry
  // Starting a thread costs about 50 us, 50 000 entries' worth.
  static constexpr long kThreadShare = 50000;
  int split_ = 0;                     // columns from split_ on go to a second thread; 0: none
  // sums_ (+ secondSums_) = C p + P q, points packed as [x y z 0].
  void sum(const MatrixX3& p, const MatrixX3& q);
  std::vector<double> p_, q_, sums_, secondSums_;  // four per vertex: x, y, z, 0
};

}  // namespace dynsub
