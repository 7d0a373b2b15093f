#include "dynsub/Trust.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "dynsub/ParallelFor.h"
#include "dynsub/Percentile.h"
#include "dynsub/Segmentation.h"

namespace dynsub {
namespace {

// Each query's distance to the nearest of `points` (brute force: a few
// hundred points against a surface's tens of thousands).
std::vector<double> nearestDistances(const MatrixX3& queries, const MatrixX3& points) {
  std::vector<double> d(static_cast<std::size_t>(queries.rows()));
  parallelFor(queries.rows(), threadsWorth(queries.rows() * points.rows() / 64), [&](Eigen::Index i) {
    d[static_cast<std::size_t>(i)] = std::sqrt((points.rowwise() - queries.row(i)).rowwise().squaredNorm().minCoeff());
  });
  return d;
}

MatrixX3 rows(const std::vector<Vector3>& points) {
  MatrixX3 m(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) m.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  return m;
}

// The area of the convex hull of points in a plane (Andrew's monotone chain).
double hullArea(std::vector<Eigen::Vector2d> p) {
  if (p.size() < 3) return 0;
  std::sort(p.begin(), p.end(),
            [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> hull(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {  // lower hull
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {  // upper hull
    while (k >= lower && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  double twice = 0;
  for (std::size_t i = 0; i + 1 < k; ++i) twice += hull[i].x() * hull[i + 1].y() - hull[i + 1].x() * hull[i].y();
  return std::abs(twice) / 2;
}

// The volume the clicks' slices outline (TrustMeasures::volumeRatio); 0 with
// fewer than two slices of 3 or more clicks.
double slicesVolume(const TrustEvidence& e) {
  if (e.sliceNormal.isZero() || e.clicks.size() < 6) return 0;
  const Vector3 n = e.sliceNormal.normalized();
  const Vector3 u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<Vector3> sorted = e.clicks;
  std::sort(sorted.begin(), sorted.end(), [&n](const Vector3& a, const Vector3& b) { return a.dot(n) < b.dot(n); });
  std::vector<std::pair<double, double>> slices;  // position along n, area
  for (std::size_t first = 0; first < sorted.size();) {
    std::size_t last = first + 1;
    while (last < sorted.size() && sorted[last].dot(n) - sorted[last - 1].dot(n) <= e.onSlice) ++last;
    std::vector<Eigen::Vector2d> projected;
    double along = 0;
    for (std::size_t i = first; i < last; ++i) {
      projected.emplace_back(sorted[i].dot(u), sorted[i].dot(v));
      along += sorted[i].dot(n);
    }
    const double area = hullArea(projected);
    if (area > 0) slices.emplace_back(along / static_cast<double>(last - first), area);
    first = last;
  }
  double volume = 0;
  for (std::size_t i = 0; i + 1 < slices.size(); ++i)
    volume += 0.5 * (slices[i].second + slices[i + 1].second) * (slices[i + 1].first - slices[i].first);
  return volume;
}

std::string fixed(double value, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

}  // namespace

TrustMeasures measureTrust(const TriangleSurface& result, double resultVolume, const TrustEvidence& evidence) {
  TrustMeasures m;
  m.outsideRegion = evidence.outsideRegion;
  m.atImageSide = evidence.atImageSide;
  m.leakedInImage = evidence.leakedInImage;
  m.insideShift = evidence.insideShift;
  const MatrixX3 clicks = rows(evidence.clicks), outline = rows(evidence.outline);
  const double volume = evidence.volume > 0 ? evidence.volume : slicesVolume(evidence);
  if (volume > 0) m.volumeRatio = resultVolume / volume;
  if (evidence.initialVolume > 0) m.initialRatio = resultVolume / evidence.initialVolume;
  MatrixX3 points(clicks.rows() + outline.rows(), 3);
  points << clicks, outline;
  if (points.rows() > 0 && result.points.rows() > 0) {
    const std::vector<double> far = nearestDistances(result.points, points);
    m.farthestFromEvidence = *std::max_element(far.begin(), far.end());
  }
  if (outline.rows() > 0 && result.points.rows() > 0)
    m.outlineDistance = percentile(nearestDistances(outline, result.points), 0.9);
  if (!evidence.clicksToAtlas.empty()) m.clicksToAtlas = percentile(evidence.clicksToAtlas, 0.9);
  if (!evidence.sliceNormal.isZero() && !evidence.clicks.empty()) {
    const Vector3 n = evidence.sliceNormal.normalized();
    const Eigen::VectorXd along = clicks * n;
    const double span = along.maxCoeff() - along.minCoeff();
    if (span > 0) m.marchShare = evidence.march / span;
  }
  return m;
}

std::vector<TrustFlag> trustFlags(const TrustMeasures& m, const TrustEvidence& evidence) {
  std::vector<TrustFlag> flags;
  if (evidence.oneClick)
    flags.push_back({"one_click",
                     "one click inside and nothing else: only the click's tissue bounds the result, which on the "
                     "evaluation's subjects is wrong (Dice under 0.7) more often than not; add boundary clicks on "
                     "a few slices, or an atlas (--init atlas --inside)"});
  // The threshold of segment()'s own warning (Segmentation.h).
  if (m.initialRatio < kCollapsedBelow)
    flags.push_back({"collapsed", "the result encloses " + fixed(100 * m.initialRatio, 0) +
                                      " % of the initial model's volume: it has collapsed (give clicks on more "
                                      "slices, or start closer to the structure's boundary)"});
  if (m.volumeRatio < kTrustSmallBelow)
    flags.push_back(
        {"small", "the result encloses " + fixed(100 * m.volumeRatio, 0) + " % of the volume of " +
                      (evidence.volume > 0 ? "the atlas's structure" : "the outlines the clicks' slices give") +
                      ": it has probably shrunk away from the boundary between the clicks"});
  if (m.clicksToAtlas > kTrustAtlasClicksApart)
    flags.push_back({"atlas_clicks_apart", "a tenth of the clicks lie " + fixed(m.clicksToAtlas, 1) +
                                               " mm or more from the atlas's structure: the atlas or the clicks "
                                               "are off (check the registration, or the clicks' structure)"});
  if (m.outlineDistance > kTrustMovedFromAtlas)
    flags.push_back({"moved_from_atlas", "a tenth of the atlas's boundary points lie " + fixed(m.outlineDistance, 1) +
                                             " mm or more from the result: the image's edges pulled it away from "
                                             "the atlas (check it there, or add clicks)"});
  if (m.insideShift > kTrustMovedToClick)
    flags.push_back({"moved_to_click",
                     "the click inside (--inside) lay outside the atlas's structure carried to "
                     "the image, which was moved " +
                         fixed(m.insideShift, 1) +
                         " mm to hold it: a click in a neighbouring structure, the other "
                         "hemisphere or the other convention (RAS read as LPS) moves it there; "
                         "check the click"});
  // A structure the scan cuts also leaves the region, at the image's side,
  // where a wider region cannot follow: that is said, and not counted as a
  // leak.
  if (m.atImageSide > kAtImageSideAbove)
    flags.push_back({"cut_by_image_side", fixed(100 * m.atImageSide, 1) +
                                              " % of the surface lies at the image's side or beyond it: the "
                                              "structure probably continues past the scan, and its volume is a "
                                              "lower bound"});
  if (m.leakedInImage > kLeakedAbove)
    flags.push_back({"leaked", fixed(100 * m.leakedInImage, 0) +
                                   " % of the surface left the region of interest, where no image force holds it"});
  return flags;
}

}  // namespace dynsub
