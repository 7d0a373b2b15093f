#pragma once
// Gauss-Legendre quadrature on [0, 1]: n nodes integrate polynomials of degree
// <= 2n - 1 exactly.
#include <vector>

namespace dynsub {

struct QuadratureRule {
  std::vector<double> nodes;    // in (0, 1), increasing
  std::vector<double> weights;  // sum to 1
};

// n in 1..64; throws dynsub::Error otherwise.
QuadratureRule gaussLegendre(int n);

}  // namespace dynsub
