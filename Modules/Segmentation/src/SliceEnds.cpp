#include "dynsub/SliceEnds.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "RobustStatistics.h"
#include "dynsub/Error.h"

namespace dynsub {
namespace {

// Step 1: the axis whose landmark positions (continuous voxel index) fall on
// the fewest distinct slices, or -1. Positions within kOnSliceVoxels of the
// previous one join its slice, and a slice may span no more than that: on
// an axis of thick voxels, a narrow structure's clicks from other slices lie
// a fraction of a voxel apart and would otherwise chain into a few
// "slices" (a caudate three voxels wide clicked on coronal slices of an
// image with 3 mm voxels from left to right).
int sliceAxis(const std::vector<Vector3>& index, int* slices) {
  int best = -1, fewest = static_cast<int>(index.size()) / 3 + 1;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> along;
    for (const Vector3& p : index) along.push_back(p(a));
    std::sort(along.begin(), along.end());
    int distinct = 1;
    double sliceStart = along.front();
    bool onSlices = true;
    for (std::size_t i = 1; i < along.size(); ++i) {
      if (along[i] - along[i - 1] > kOnSliceVoxels) {
        ++distinct;
        sliceStart = along[i];
      } else if (along[i] - sliceStart > kOnSliceVoxels) {
        onSlices = false;
      }
    }
    if (onSlices && distinct >= 2 && distinct < fewest) {
      fewest = distinct;
      best = a;
    }
  }
  *slices = best >= 0 ? fewest : 0;
  return best;
}

// The median intensity of a disk across the axis (trilinear, so that the
// march does not depend on how the disk's points fall between voxels), or
// NaN when the disk leaves the image.
double diskMedian(const Volume& image, const Vector3& centre, const Vector3& u, const Vector3& v, double radius,
                  double step) {
  const ImageGeometry& g = image.geometry;
  std::vector<double> values;
  const int n = static_cast<int>(std::ceil(radius / step));
  for (int a = -n; a <= n; ++a)
    for (int b = -n; b <= n; ++b) {
      if (a * a + b * b > n * n) continue;
      const Vector3 index = g.toIndex(centre + a * step * u + b * step * v);
      if (!g.spans(index)) return std::nan("");
      values.push_back(image.interpolate(index));
    }
  return robustStatistics(std::move(values)).median;
}

}  // namespace

void checkSliceEndOptions(const SliceEndOptions& o) {
  for (const auto& [value, name] : {std::pair{o.window, "window"}, {o.disk, "disk"}, {o.reach, "reach"},
                                    {o.stiffness, "stiffness"}})
    if (!(value > 0) || !std::isfinite(value))
      throw Error(std::string("the slice ends' ") + name + " must be a finite number > 0");
  if (!(o.gap >= 0) || !std::isfinite(o.gap)) throw Error("the slice ends' gap must be a finite number >= 0");
  if (!(o.endLevel >= 0 && o.endLevel <= 1)) throw Error("the slice ends' end level must be a number in [0, 1]");
  if (!(o.endLevelAtReach >= 0 && o.endLevelAtReach <= 1))
    throw Error("the slice ends' end level at reach must be a number in [0, 1]");
  if (!(o.pressure >= 0) || !std::isfinite(o.pressure))
    throw Error("the pressure beyond the end slices must be a finite number >= 0");
}

SliceEnds findSliceEnds(const Volume& image, const std::vector<Landmark>& landmarks, const ControlMesh& initial,
                        const SliceEndOptions& options) {
  checkSliceEndOptions(options);
  SliceEnds result;
  if (landmarks.size() < 4) return result;
  const ImageGeometry& g = image.geometry;
  std::vector<Vector3> index;
  for (const Landmark& l : landmarks) index.push_back(g.toIndex(l.position));
  const int axis = sliceAxis(index, &result.slices);
  if (axis < 0) return result;
  result.axis = axis;
  // Step 2.
  const std::optional<RobustStatistics> inside = insideIntensities(image, initial);
  if (!inside) return result;
  result.median = inside->median;
  result.spread = inside->spread;
  if (!(inside->spread > 0) || !std::isfinite(inside->median)) return result;
  const double halfWidth = options.window * inside->spread;

  double first = index[0](axis), last = index[0](axis);
  for (const Vector3& p : index) {
    first = std::min(first, p(axis));
    last = std::max(last, p(axis));
  }
  const Vector3 along = g.direction.col(axis).normalized();
  const Vector3 u = g.direction.col((axis + 1) % 3).normalized(), v = g.direction.col((axis + 2) % 3).normalized();
  const double spacing = g.spacing(axis), span = (last - first) * spacing;
  const double step = 0.5 * g.spacing.minCoeff();
  const auto clicksOn = [&](double slice) {
    std::vector<Vector3> onSlice;
    for (std::size_t i = 0; i < landmarks.size(); ++i)
      if (std::abs(index[i](axis) - slice) <= kOnSliceVoxels) onSlice.push_back(landmarks[i].position);
    return onSlice;
  };
  const auto centroid = [](const std::vector<Vector3>& points) {
    Vector3 centre = Vector3::Zero();
    for (const Vector3& p : points) centre += p;
    return Vector3(centre / static_cast<double>(points.size()));
  };
  const auto rmsRadius = [&](const std::vector<Vector3>& points) {
    const Vector3 centre = centroid(points);
    double squared = 0;
    for (const Vector3& p : points) squared += (p - centre).squaredNorm();
    return std::sqrt(squared / static_cast<double>(points.size()));
  };
  for (const auto& [slice, outward] : {std::pair{first, -1.0}, {last, 1.0}}) {
    // Step 3: the end slice's landmarks, their centroid and rms radius.
    const std::vector<Vector3> onSlice = clicksOn(slice);
    if (onSlice.size() < 3) continue;
    const Vector3 centre = centroid(onSlice);
    const double rms = rmsRadius(onSlice);
    const double radius = std::max(g.spacing.maxCoeff(), options.disk * rms);
    // The next clicked slice inwards: whether the clicks widen fast toward this end.
    double inner = outward < 0 ? last : first;
    for (const Vector3& p : index)
      if (std::abs(p(axis) - slice) > kOnSliceVoxels && std::abs(p(axis) - slice) < std::abs(inner - slice))
        inner = p(axis);
    const std::vector<Vector3> innerClicks = clicksOn(inner);
    SliceEnd end;
    end.side = outward < 0 ? -1 : 1;
    end.start = end.marchStart = end.end = centre;
    for (const Vector3& p : onSlice) {
      const Vector3 across = (p - centre) - (p - centre).dot(along) * along;
      end.sliceRadius = std::max(end.sliceRadius, across.norm());
    }
    const double longest = options.reach * span;
    // The end's own level at a point of the end slice: the median of the
    // disks there and two steps inward, where it lies within the window of
    // the model's median.
    const auto ownLevelAt = [&](const Vector3& point) -> std::optional<double> {
      std::vector<double> own;
      for (int k = 0; k < 3; ++k) {
        const double m = diskMedian(image, point - outward * k * step * along, u, v, radius, step);
        if (std::isfinite(m)) own.push_back(m);
      }
      if (own.empty()) return std::nullopt;
      const double median = robustStatistics(std::move(own)).median;
      if (std::abs(median - inside->median) > halfWidth) return std::nullopt;
      return median;
    };
    std::optional<double> ownLevel = ownLevelAt(centre);
    // Step 3's march from end.marchStart with the window's centre `share` of
    // the way to the end's level: how far it went (mm), its window and
    // whether it saw no end in `end`.
    const auto march = [&](double share) {
      const double level = inside->median + (ownLevel ? share * (*ownLevel - inside->median) : 0.0);
      end.low = level - halfWidth;
      end.high = level + halfWidth;
      int outside = 0;
      double reached = 0;
      for (double t = step; t <= longest; t += step) {
        const double m = diskMedian(image, end.marchStart + outward * t * along, u, v, radius, step);
        if (!std::isfinite(m)) break;
        if (m < end.low || m > end.high) {
          if (++outside == 2) break;
        } else {
          outside = 0;
          reached = t;
        }
      }
      end.stoppedByReach = outside < 2 && reached + 2 * step > longest;
      return reached;
    };
    double reached = march(options.endLevel);
    // A section can wrap around other tissue (a cerebellum's near the midline
    // around its white matter and the fourth ventricle): where the centroid's
    // disks are not the structure's tissue and the march from there stopped
    // within `gap`, as if the clicks reached the end, it starts again from a
    // point inside the section whose level is nearest the model's median: a
    // third or two thirds of the way to one of the clicks, which lie on the
    // boundary, where a disk would straddle it.
    if (!ownLevel && reached <= options.gap && !end.stoppedByReach) {
      for (const Vector3& p : onSlice)
        for (const double toClick : {1.0 / 3.0, 2.0 / 3.0}) {
          const Vector3 point = centre + toClick * (p - centre);
          const std::optional<double> level = ownLevelAt(point);
          if (level && (!ownLevel || std::abs(*level - inside->median) < std::abs(*ownLevel - inside->median))) {
            ownLevel = level;
            end.marchStart = point;
          }
        }
      if (ownLevel) reached = march(options.endLevel);
    }
    if (end.stoppedByReach && ownLevel && options.endLevelAtReach != options.endLevel) {
      reached = march(options.endLevelAtReach);
      end.marchedAgain = true;
    }
    end.length = reached;
    end.end = end.marchStart + outward * reached * along;
    // Step 4.
    end.sprung = reached > options.gap && (!end.stoppedByReach || options.springAtReach);
    // A structure whose clicked cross-sections still widen fast toward this
    // end (a caudate's head) keeps its width past it; one whose cross-sections
    // narrow, or widen slowly near its widest, goes on as an ellipsoid.
    end.widening = innerClicks.size() >= 3 && rms > kTaperWidening * rmsRadius(innerClicks);
    end.tapered = end.sprung && options.taper && !end.widening;
    result.ends.push_back(end);
    if (end.sprung) {
      const std::string name = outward < 0 ? "slice end (first)" : "slice end (last)";
      result.springs.push_back({name, end.end});
      // Halfway, the end slice's clicks drawn in as an ellipsoid's cross-section narrows.
      if (end.tapered)
        for (const Vector3& p : onSlice)
          result.springs.push_back({name + " taper", centre + std::sqrt(0.75) * (p - centre) +
                                                         outward * 0.5 * reached * along});
    }
  }
  return result;
}

}  // namespace dynsub
