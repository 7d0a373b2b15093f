#include "dynsub/SelfIntersection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "dynsub/ParallelFor.h"

namespace dynsub {

namespace {

// Whether the segment from `o` to `o + d` passes through the triangle (a, b, c)
// (Möller and Trumbore's ray test, cut to the segment). A segment in the
// triangle's plane does not count: two triangles that cross always have an
// edge of one through the other's interior, out of its plane.
bool segmentCrossesTriangle(const Vector3& o, const Vector3& d, const Vector3& a, const Vector3& b, const Vector3& c) {
  const Vector3 e1 = b - a, e2 = c - a;
  const Vector3 p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) <= 1e-12 * d.norm() * e1.norm() * e2.norm()) return false;
  const Vector3 s = o - a;
  const double u = s.dot(p) / det;
  if (u < 0.0 || u > 1.0) return false;
  const Vector3 q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return false;
  const double t = e2.dot(q) / det;
  return t >= 0.0 && t <= 1.0;
}

}  // namespace

SelfIntersection findSelfIntersections(const TriangleSurface& surface) {
  SelfIntersection result;
  const int count = static_cast<int>(surface.triangles.size());
  if (count == 0) return result;
  const MatrixX3& points = surface.points;
  const Vector3 low = points.colwise().minCoeff().transpose(), high = points.colwise().maxCoeff().transpose();
  // Samples this close are one (a sharp crease's two sides).
  const double coincident = 1e-9 * (high - low).norm();

  // Each triangle's corners side by side, its bounding box, and its plane,
  // n . x = offset: a triangle wholly on one side of another's plane does not
  // cross it, which settles most pairs of near neighbours before the edge tests.
  struct Triangle {
    std::array<Vector3, 3> corner;
    Vector3 low, high, normal;
    double offset;
    Eigen::Vector3i firstCell;  // the grid cell of `low`
  };
  std::vector<Triangle> triangles(count);
  double diagonals = 0.0;
  for (int t = 0; t < count; ++t) {
    Triangle& tri = triangles[t];
    for (int k = 0; k < 3; ++k) tri.corner[k] = points.row(surface.triangles[t][k]).transpose();
    tri.low = tri.corner[0].cwiseMin(tri.corner[1]).cwiseMin(tri.corner[2]);
    tri.high = tri.corner[0].cwiseMax(tri.corner[1]).cwiseMax(tri.corner[2]);
    tri.normal = (tri.corner[1] - tri.corner[0]).cross(tri.corner[2] - tri.corner[0]);
    tri.offset = tri.normal.dot(tri.corner[0]);
    diagonals += (tri.high - tri.low).norm();
  }
  // Cells twice the boxes' mean diagonal, numbered at most 0-1000 along each
  // axis, so that a cell's number (10 bits an axis) and a triangle's fit in
  // one 64-bit key.
  const double cellSize = std::max(2.0 * diagonals / count, (high - low).maxCoeff() / 1000.0);
  if (!(cellSize > 0.0)) return result;  // every sample at one point: nothing to cross
  auto cellOf = [&](const Vector3& x) { return ((x - low) / cellSize).array().floor().cast<int>().matrix().eval(); };
  auto cellNumber = [](const Eigen::Vector3i& cell) {
    return std::uint64_t(cell.x()) | std::uint64_t(cell.y()) << 10 | std::uint64_t(cell.z()) << 20;
  };

  // (cell << 32 | triangle) for every cell a triangle's box meets, sorted by
  // cell. A triangle whose box meets more than kLongCells cells is long: where
  // a few long triangles lie among many short ones (a stretched element), the
  // cells are the short ones' size and a long one's box could meet up to 1001^3
  // of them, so long triangles are kept out of the grid and tested against
  // every triangle whose box they meet instead. The grid then holds at most
  // kLongCells entries a triangle; an even tessellation puts about 3 a triangle.
  constexpr std::int64_t kLongCells = 64;
  std::vector<std::uint64_t> entries;
  entries.reserve(3 * static_cast<std::size_t>(count));
  std::vector<int> longOnes;
  std::vector<char> isLong(count, 0);
  for (int t = 0; t < count; ++t) {
    const Eigen::Vector3i first = cellOf(triangles[t].low), last = cellOf(triangles[t].high);
    triangles[t].firstCell = first;
    if ((last - first + Eigen::Vector3i::Ones()).cast<std::int64_t>().prod() > kLongCells) {
      longOnes.push_back(t);
      isLong[t] = 1;
      continue;
    }
    for (int z = first.z(); z <= last.z(); ++z)
      for (int y = first.y(); y <= last.y(); ++y)
        for (int x = first.x(); x <= last.x(); ++x) entries.push_back(cellNumber({x, y, z}) << 32 | std::uint64_t(t));
  }
  std::sort(entries.begin(), entries.end());

  auto boxesMeet = [](const Triangle& a, const Triangle& b) {
    return a.low.x() <= b.high.x() && b.low.x() <= a.high.x() && a.low.y() <= b.high.y() && b.low.y() <= a.high.y() &&
           a.low.z() <= b.high.z() && b.low.z() <= a.high.z();
  };
  // Neighbours meet at a common sample, or at two coincident ones.
  auto shareACorner = [&](int a, int b) {
    const auto& p = surface.triangles[a];
    const auto& q = surface.triangles[b];
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l)
        if (p[k] == q[l]) return true;
    for (const Vector3& x : triangles[a].corner)
      for (const Vector3& y : triangles[b].corner)
        if ((x - y).cwiseAbs().maxCoeff() <= coincident) return true;
    return false;
  };
  auto oneSide = [](const Triangle& a, const Triangle& b) {
    const double d0 = b.normal.dot(a.corner[0]) - b.offset, d1 = b.normal.dot(a.corner[1]) - b.offset,
                 d2 = b.normal.dot(a.corner[2]) - b.offset;
    return (d0 > 0.0 && d1 > 0.0 && d2 > 0.0) || (d0 < 0.0 && d1 < 0.0 && d2 < 0.0);
  };
  auto edgeThrough = [](const Triangle& a, const Triangle& b) {
    for (int k = 0; k < 3; ++k) {
      const Vector3& o = a.corner[k];
      if (segmentCrossesTriangle(o, a.corner[(k + 1) % 3] - o, b.corner[0], b.corner[1], b.corner[2])) return true;
    }
    return false;
  };
  // Whether triangles a and b, whose boxes meet, cross.
  auto crosses = [&](int a, int b) {
    const Triangle& ta = triangles[a];
    const Triangle& tb = triangles[b];
    if (shareACorner(a, b) || oneSide(ta, tb) || oneSide(tb, ta)) return false;
    return edgeThrough(ta, tb) || edgeThrough(tb, ta);
  };

  // The cells in two halves, one per thread where there are two: the pairs
  // each finds, in the cell that holds the low corner of their boxes'
  // overlap, so that a pair is counted once.
  std::vector<std::size_t> split{0, entries.size() / 2, entries.size()};
  while (split[1] > 0 && split[1] < entries.size() && entries[split[1]] >> 32 == entries[split[1] - 1] >> 32)
    ++split[1];
  std::array<std::vector<std::pair<int, int>>, 2> found;
  // A second thread from 8192 entries (about 4,000 triangles), whose pair
  // loop takes most of a millisecond, far above a hand-off's tens of microseconds.
  parallelFor(2, static_cast<Eigen::Index>(entries.size() / 4096), [&](Eigen::Index half) {
    std::vector<int> members;
    for (std::size_t begin = split[half]; begin < split[half + 1];) {
      const std::uint64_t cell = entries[begin] >> 32;
      members.clear();
      std::size_t end = begin;
      for (; end < split[half + 1] && entries[end] >> 32 == cell; ++end)
        members.push_back(static_cast<int>(entries[end] & 0xffffffffu));
      for (std::size_t i = 0; i < members.size(); ++i) {
        const Triangle& a = triangles[members[i]];
        for (std::size_t j = i + 1; j < members.size(); ++j) {
          const Triangle& b = triangles[members[j]];
          if (!boxesMeet(a, b) || cellNumber(a.firstCell.cwiseMax(b.firstCell)) != cell) continue;
          if (crosses(members[i], members[j])) found[half].push_back({members[i], members[j]});
        }
      }
      begin = end;
    }
  });
  // Each long triangle against every other triangle, a pair of long ones once.
  for (int a : longOnes)
    for (int b = 0; b < count; ++b)
      if (b != a && !(isLong[b] && b < a) && boxesMeet(triangles[a], triangles[b]) && crosses(a, b))
        found[0].push_back({a, b});

  std::vector<char> crossing(count, 0);
  for (const auto& pairs : found) {
    result.trianglePairs += static_cast<int>(pairs.size());
    for (const auto& [a, b] : pairs) crossing[a] = crossing[b] = 1;
  }
  double area = 0.0, crossingArea = 0.0;
  result.boundsMin = Vector3::Constant(std::numeric_limits<double>::infinity());
  result.boundsMax = -result.boundsMin;
  for (int t = 0; t < count; ++t) {
    const double a = 0.5 * triangles[t].normal.norm();
    area += a;
    if (!crossing[t]) continue;
    crossingArea += a;
    result.boundsMin = result.boundsMin.cwiseMin(triangles[t].low);
    result.boundsMax = result.boundsMax.cwiseMax(triangles[t].high);
    result.triangles.push_back(t);
  }
  if (result.triangles.empty()) result.boundsMin = result.boundsMax = Vector3::Zero();
  result.areaPercent = area > 0.0 ? 100.0 * crossingArea / area : 0.0;
  return result;
}

}  // namespace dynsub
