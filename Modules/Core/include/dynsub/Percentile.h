#pragma once
// The value below which a fraction of a sample lies.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace dynsub {

// The element at rank fraction * (n - 1), rounded down, of `values` as if
// sorted (std::nth_element on the copy taken); 0 for an empty sample.
template <typename T>
T percentile(std::vector<T> values, double fraction) {
  if (values.empty()) return T(0);
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(fraction * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

}  // namespace dynsub
