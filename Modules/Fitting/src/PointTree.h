#pragma once
// A k-d tree over an N x 3 matrix's rows (nanoflann), without a copy of them.
#include <nanoflann.hpp>

#include "dynsub/Types.h"

namespace dynsub {

struct PointRows {
  const MatrixX3& points;
  size_t kdtree_get_point_count() const { return static_cast<size_t>(points.rows()); }
  double kdtree_get_pt(size_t i, size_t d) const { return points(static_cast<Eigen::Index>(i), d); }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using PointTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointRows>, PointRows, 3>;

}  // namespace dynsub
