#include "dynsub/SeedGrowth.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "dynsub/RegionGrowing.h"
#include "RobustStatistics.h"
#include "dynsub/Error.h"

namespace dynsub {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kGuardWindow = 2.5;  // the leak guard's narrower window
constexpr double kNarrowerWindow = 0.8;  // SeedRegion::narrowerWindowVolume

}  // namespace

void checkSeedOptions(const SeedOptions& o) {
  auto positive = [](double value, const char* name) {
    if (!(value > 0) || !std::isfinite(value))
      throw Error(std::string("the seed's ") + name + " must be a finite number > 0");
  };
  positive(o.statsRadius, "statistics radius");
  positive(o.window, "intensity window");
  positive(o.reach, "reach");
  if (!(o.opening >= 0) || !std::isfinite(o.opening)) throw Error("the seed's opening must be a finite number >= 0");
  if (o.boundaryPoints < 4) throw Error("the seed's region needs at least 4 boundary points");
}

namespace {

// The part of the image the growth may fill: `reach` mm around the click's
// voxel along each axis, clamped to the image.
struct SeedBox {
  Volume image;
  std::array<int, 3> first{};  // in the full image
  std::array<int, 3> seed{};   // the click's voxel, in the box
  long long seedOffset = 0;
};

SeedBox boxAround(const Volume& image, const Vector3& click, double reach) {
  const ImageGeometry& full = image.geometry;
  const Vector3 index = full.toIndex(click);
  SeedBox box;
  std::array<int, 3> size{};
  for (int a = 0; a < 3; ++a) {
    const int voxel = std::clamp(static_cast<int>(std::lround(index(a))), 0, full.size[a] - 1);
    const int steps = static_cast<int>(std::ceil(reach / full.spacing(a)));
    box.first[a] = std::max(0, voxel - steps);
    size[a] = std::min(full.size[a], voxel + steps + 1) - box.first[a];
    box.seed[a] = voxel - box.first[a];
  }
  box.image = cropVolume(image, box.first, size);
  box.seedOffset = box.image.geometry.offset(box.seed[0], box.seed[1], box.seed[2]);
  return box;
}

// Step 1: the median and spread of the intensities within `radius` mm of the
// click, the spread at least 1 % of the box's 1st-99th percentile range.
RobustStatistics appearanceAt(const SeedBox& box, double radius) {
  const ImageGeometry& g = box.image.geometry;
  const auto [si, sj, sk] = box.seed;
  std::vector<double> ball;
  int r[3];
  for (int a = 0; a < 3; ++a) r[a] = static_cast<int>(std::ceil(radius / g.spacing(a)));
  for (int k = sk - r[2]; k <= sk + r[2]; ++k)
    for (int j = sj - r[1]; j <= sj + r[1]; ++j)
      for (int i = si - r[0]; i <= si + r[0]; ++i) {
        if (!g.contains(i, j, k)) continue;
        const Vector3 d = (Vector3(i - si, j - sj, k - sk).array() * g.spacing.array()).matrix();
        if (d.norm() <= radius) ball.push_back(box.image.at(i, j, k));
      }
  RobustStatistics appearance = robustStatistics(std::move(ball));
  std::vector<float> sorted(box.image.voxels);
  const auto percentile = [&](double p) {
    auto at = sorted.begin() + static_cast<long long>(p * (sorted.size() - 1));
    std::nth_element(sorted.begin(), at, sorted.end());
    return static_cast<double>(*at);
  };
  const double range = percentile(0.99) - percentile(0.01);
  appearance.spread = std::max(appearance.spread, 0.01 * range);
  if (!std::isfinite(appearance.median) || !std::isfinite(appearance.spread))
    throw Error("the image's intensities near the seed are not finite");
  return appearance;
}

// Step 2: the voxels within [low, high] 6-connected to the click.
std::vector<std::uint8_t> growThrough(const SeedBox& box, double low, double high) {
  const std::vector<float>& voxels = box.image.voxels;
  std::vector<std::uint8_t> like(voxels.size());
  for (std::size_t o = 0; o < voxels.size(); ++o) like[o] = voxels[o] >= low && voxels[o] <= high;
  like[box.seedOffset] = 1;  // the click itself is inside, whatever its own value
  return connectedTo(like, box.image.geometry, {box.seedOffset});
}

// Steps 3 and 4 on a grown region, then its boundary: fills `region`'s mask,
// boundary and touchesReach. Throws when the opening leaves nothing near the click.
void shapeRegion(const SeedBox& box, const std::vector<std::uint8_t>& grown, const std::vector<float>& depth,
                 double opening, int boundaryPoints, SeedRegion& region) {
  const ImageGeometry& g = box.image.geometry;
  const long long seed = box.seedOffset;
  const auto [si, sj, sk] = box.seed;
  // 3. Opening.
  std::vector<std::uint8_t> kept = grown;
  if (opening > 0) {
    const std::vector<std::uint8_t> core = coreOf(grown, depth, opening);
    // The core voxel nearest the click, within the opening's reach of it.
    long long start = -1;
    double nearest = kInfinity;
    if (core[seed]) {
      start = seed;
    } else {
      const int reach = static_cast<int>(std::ceil(2 * opening / g.spacing.minCoeff())) + 1;
      for (int k = std::max(0, sk - reach); k <= std::min(g.size[2] - 1, sk + reach); ++k)
        for (int j = std::max(0, sj - reach); j <= std::min(g.size[1] - 1, sj + reach); ++j)
          for (int i = std::max(0, si - reach); i <= std::min(g.size[0] - 1, si + reach); ++i) {
            const long long o = g.offset(i, j, k);
            const double d = (Vector3(i - si, j - sj, k - sk).array() * g.spacing.array()).matrix().norm();
            if (core[o] && d < nearest && d <= 2 * opening + g.spacing.maxCoeff()) {
              nearest = d;
              start = o;
            }
          }
    }
    if (start < 0)
      throw Error("the tissue at the seed is thinner than the seed's opening (" + std::to_string(opening) +
                  " mm): click deeper inside the structure, or lower the opening");
    kept = openFrom(grown, core, g, opening, {start});
  }

  // 4. Holes.
  kept = fillHoles(kept, g);

  // The boundary, and whether the region touches its box.
  const std::vector<Vector3> faces = boundaryFaces(kept, g, &region.touchesReach);
  if (faces.size() < 4) throw Error("the region grown from the seed is too small to start a surface from");
  region.mask = Mask{g, std::move(kept)};
  region.boundary.clear();
  const std::vector<Vector3> spread = farthestPointSample(faces, region.click, boundaryPoints);
  for (std::size_t p = 0; p < spread.size(); ++p)
    region.boundary.push_back({"seed boundary " + std::to_string(p + 1), spread[p]});
}

}  // namespace

namespace {

// The leak guard (see the header): a narrower window, then wider openings,
// until the region stays inside its reach; the last region grown otherwise.
// `base` holds the click and its appearance.
SeedRegion guardedRegion(const SeedBox& box, const SeedRegion& base, const SeedOptions& options) {
  std::vector<double> windows = {options.window};
  if (options.window > kGuardWindow) windows.push_back(kGuardWindow);
  SeedRegion result;
  std::string failure;
  for (const double window : windows) {
    SeedRegion grownThrough = base;
    grownThrough.window = window;
    grownThrough.low = base.median - window * base.spread;
    grownThrough.high = base.median + window * base.spread;
    const std::vector<std::uint8_t> grown = growThrough(box, grownThrough.low, grownThrough.high);
    grownThrough.grownVoxels = std::count(grown.begin(), grown.end(), 1);
    const std::vector<float> depth = depthInside(grown, box.image.geometry);  // for every opening
    for (const double extra : {0.0, 1.0, 2.0}) {
      SeedRegion attempt = grownThrough;
      attempt.opening = options.opening + extra;
      try {
        shapeRegion(box, grown, depth, attempt.opening, options.boundaryPoints, attempt);
      } catch (const Error& e) {
        failure = e.what();  // opened away at the click: try the next
        continue;
      }
      result = std::move(attempt);
      if (!result.touchesReach) return result;
    }
  }
  if (result.boundary.empty()) throw Error(failure);
  return result;
}

// How much of `region` the last part of its window added: the volume (mm^3)
// of the region the same growth and opening give through a window
// kNarrowerWindow as wide, 0 when that opening leaves nothing at the click.
double narrowerWindowVolume(const SeedBox& box, const SeedRegion& region, int boundaryPoints) {
  const double window = kNarrowerWindow * region.window;
  const std::vector<std::uint8_t> grown =
      growThrough(box, region.median - window * region.spread, region.median + window * region.spread);
  SeedRegion smaller;
  smaller.click = region.click;  // what shapeRegion spreads the boundary points from
  try {
    shapeRegion(box, grown, depthInside(grown, box.image.geometry), region.opening, boundaryPoints, smaller);
  } catch (const Error&) {
    return 0.0;
  }
  return regionVolume(smaller);
}

}  // namespace

SeedRegion growFromSeed(const Volume& image, const Vector3& click, const SeedOptions& options) {
  checkSeedOptions(options);
  if (!click.allFinite() || !image.geometry.covers(click)) {
    std::ostringstream message;
    message << "the seed (" << click.x() << ", " << click.y() << ", " << click.z()
            << ") mm LPS lies outside the image";
    throw Error(message.str());
  }
  // The box and the appearance at the click are the same for every attempt.
  const SeedBox box = boxAround(image, click, options.reach);
  SeedRegion base;
  base.click = click;
  base.first = box.first;
  const RobustStatistics appearance = appearanceAt(box, options.statsRadius);
  base.median = appearance.median;
  base.spread = appearance.spread;
  SeedRegion result = guardedRegion(box, base, options);
  result.narrowerWindowVolume = narrowerWindowVolume(box, result, options.boundaryPoints);
  return result;
}

double regionVolume(const SeedRegion& region) { return region.mask.count() * region.mask.geometry.spacing.prod(); }

namespace {

// Grew more than kLeakGrowth times over the last fifth of its window.
bool hangsOnWindow(const SeedRegion& region) {
  return regionVolume(region) > kLeakGrowth * region.narrowerWindowVolume;
}

}  // namespace

bool probablyLeaked(const SeedRegion& region) {
  return region.touchesReach || (hangsOnWindow(region) && region.narrowerWindowVolume >= kSmallSeedRegion);
}

std::vector<std::string> seedWarnings(const SeedRegion& region) {
  std::vector<std::string> warnings;
  std::ostringstream message;
  message << std::fixed << std::setprecision(1);
  if (region.touchesReach) {
    message << "the region grown from the seed (intensities " << region.low << " to " << region.high
            << ") reached the edge of its reach even with the narrowest window and the widest opening: it has "
               "leaked into like tissue around the structure (give landmarks, or click deeper inside)";
    warnings.push_back(message.str());
    message.str("");
  }
  const double volume = regionVolume(region);
  if (!region.touchesReach && hangsOnWindow(region)) {
    message << "the region grown from the seed (" << volume << " mm^3, intensities " << region.low << " to "
            << region.high << ") is " << std::setprecision(1)
            << (region.narrowerWindowVolume > 0 ? volume / region.narrowerWindowVolume : kInfinity)
            << " times the one a window a fifth narrower gives (" << region.narrowerWindowVolume << " mm^3): ";
    if (probablyLeaked(region)) {
      message << "the last of its intensities joined like tissue to it, so it has probably leaked into a "
                 "neighbour of the structure (give landmarks, or click elsewhere inside)";
    } else {
      message << "its size hangs on the window, so it may hold only part of the structure, or run into a "
                 "neighbour (check the figures, give landmarks, or click elsewhere inside)";
    }
    warnings.push_back(message.str());
    message.str("");
  }
  if (volume < kSmallSeedRegion) {
    message << "the region grown from the seed holds only " << volume << " mm^3 (intensities " << region.low
            << " to " << region.high << ", opening " << region.opening
            << " mm): the surface starts small and may collapse (give landmarks, or click deeper inside)";
    warnings.push_back(message.str());
  }
  return warnings;
}

}  // namespace dynsub
