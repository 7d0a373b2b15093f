#include "dynsub/GaussLegendre.h"

#include <cmath>
#include <string>
#include <utility>

#include "dynsub/Error.h"

namespace dynsub {

namespace {

// P_n(x) and P_n'(x) by the three-term recurrence (|x| < 1).
std::pair<double, double> legendre(int n, double x) {
  double p0 = 1.0, p1 = x;
  for (int k = 2; k <= n; ++k) {
    const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
    p0 = p1;
    p1 = p2;
  }
  return {p1, n * (x * p1 - p0) / (x * x - 1.0)};
}

}  // namespace

QuadratureRule gaussLegendre(int n) {
  if (n < 1 || n > 64) throw Error("Gauss-Legendre rules have 1..64 nodes, not " + std::to_string(n));
  QuadratureRule rule;
  rule.nodes.resize(n);
  rule.weights.resize(n);
  // Roots of P_n on [-1, 1] by Newton's method from Chebyshev-like guesses.
  for (int i = 0; i < n; ++i) {
    double x = std::cos(M_PI * (i + 0.75) / (n + 0.5));
    for (int iteration = 0; iteration < 100; ++iteration) {
      const auto [value, derivative] = legendre(n, x);
      const double dx = value / derivative;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    const double derivative = legendre(n, x).second;  // at the converged root, for the weight
    // Map [-1, 1] to [0, 1]: nodes (1 + x)/2, weights halved; i counts from x = 1 down.
    rule.nodes[n - 1 - i] = 0.5 * (1.0 + x);
    rule.weights[n - 1 - i] = 1.0 / ((1.0 - x * x) * derivative * derivative);
  }
  return rule;
}

}  // namespace dynsub
