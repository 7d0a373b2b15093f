#include "dynsub/SeedGrowth.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "RobustStatistics.h"
#include "dynsub/Error.h"

namespace dynsub {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kGuardWindow = 2.5;  // the leak guard's narrower window

// The voxels of `allowed` 6-connected to any of `starts` (which must be allowed).
std::vector<std::uint8_t> connectedTo(const std::vector<std::uint8_t>& allowed, const ImageGeometry& g,
                                      std::vector<long long> starts) {
  std::vector<std::uint8_t> reached(allowed.size(), 0);
  for (long long start : starts) reached[start] = 1;
  std::vector<long long> stack = std::move(starts);
  const long long sx = 1, sy = g.size[0], sz = static_cast<long long>(g.size[0]) * g.size[1];
  while (!stack.empty()) {
    const long long o = stack.back();
    stack.pop_back();
    const int i = static_cast<int>(o % sy), j = static_cast<int>((o / sy) % g.size[1]),
              k = static_cast<int>(o / sz);
    const std::pair<bool, long long> neighbours[6] = {{i > 0, o - sx},           {i + 1 < g.size[0], o + sx},
                                                      {j > 0, o - sy},           {j + 1 < g.size[1], o + sy},
                                                      {k > 0, o - sz},           {k + 1 < g.size[2], o + sz}};
    for (const auto& [inside, n] : neighbours)
      if (inside && allowed[n] && !reached[n]) {
        reached[n] = 1;
        stack.push_back(n);
      }
  }
  return reached;
}


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
void shapeRegion(const SeedBox& box, const std::vector<std::uint8_t>& grown, double opening, int boundaryPoints,
                 SeedRegion& region) {
  const ImageGeometry& g = box.image.geometry;
  const long long n = g.voxelCount();
  const long long seed = box.seedOffset;
  const auto [si, sj, sk] = box.seed;
  // 3. Opening.
  std::vector<std::uint8_t> kept = grown;
  if (opening > 0) {
    Mask outside{g, std::vector<std::uint8_t>(n)};
    for (long long o = 0; o < n; ++o) outside.voxels[o] = !grown[o];
    const std::vector<float> depth = distanceTo(outside);
    std::vector<std::uint8_t> core(n);
    for (long long o = 0; o < n; ++o) core[o] = grown[o] && depth[o] > opening;
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
    const std::vector<float> away = distanceTo(Mask{g, connectedTo(core, g, {start})});
    for (long long o = 0; o < n; ++o) kept[o] = grown[o] && away[o] <= opening;
  }

  // 4. Holes: what the box's border cannot reach through the outside.
  {
    std::vector<std::uint8_t> outside(n);
    std::vector<long long> border;
    for (int k = 0; k < g.size[2]; ++k)
      for (int j = 0; j < g.size[1]; ++j)
        for (int i = 0; i < g.size[0]; ++i) {
          const long long o = g.offset(i, j, k);
          outside[o] = !kept[o];
          if (outside[o] && (i == 0 || j == 0 || k == 0 || i + 1 == g.size[0] || j + 1 == g.size[1] ||
                             k + 1 == g.size[2]))
            border.push_back(o);
        }
    const std::vector<std::uint8_t> reached = connectedTo(outside, g, std::move(border));
    for (long long o = 0; o < n; ++o) kept[o] = !reached[o];
  }

  // The boundary, and whether the region touches its box.
  std::vector<Vector3> faces;
  region.touchesReach = false;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        if (!kept[g.offset(i, j, k)]) continue;
        const int step[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
        for (const auto& s : step) {
          const int a = i + s[0], b = j + s[1], c = k + s[2];
          if (!g.contains(a, b, c)) {  // the box's side: the voxel itself (its face may be the image's edge)
            region.touchesReach = true;
            faces.push_back(g.toPhysical(Vector3(i, j, k)));
            continue;
          }
          if (!kept[g.offset(a, b, c)])
            faces.push_back(g.toPhysical(Vector3(i + 0.5 * s[0], j + 0.5 * s[1], k + 0.5 * s[2])));
        }
      }
  if (faces.size() < 4) throw Error("the region grown from the seed is too small to start a surface from");
  region.mask = Mask{g, std::move(kept)};

  // Farthest-point sampling from the boundary point nearest the click.
  std::vector<double> gap(faces.size(), kInfinity);
  std::size_t next = 0;
  for (std::size_t f = 1; f < faces.size(); ++f)
    if ((faces[f] - region.click).squaredNorm() < (faces[next] - region.click).squaredNorm()) next = f;
  const std::size_t keep = std::min<std::size_t>(faces.size(), boundaryPoints);
  region.boundary.clear();
  for (std::size_t taken = 0; taken < keep; ++taken) {
    region.boundary.push_back({"seed boundary " + std::to_string(taken + 1), faces[next]});
    gap[next] = 0;
    std::size_t farthest = 0;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      gap[f] = std::min(gap[f], (faces[f] - faces[next]).squaredNorm());
      if (gap[f] > gap[farthest]) farthest = f;
    }
    next = farthest;
  }
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
  // The leak guard (see the header): a narrower window, then wider openings,
  // until the region stays inside its reach; the last region grown otherwise.
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
    for (const double extra : {0.0, 1.0, 2.0}) {
      SeedRegion attempt = grownThrough;
      attempt.opening = options.opening + extra;
      try {
        shapeRegion(box, grown, attempt.opening, options.boundaryPoints, attempt);
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
  const double volume = region.mask.count() * region.mask.geometry.spacing.prod();
  if (volume < kSmallSeedRegion) {
    message << "the region grown from the seed holds only " << volume << " mm^3 (intensities " << region.low
            << " to " << region.high << ", opening " << region.opening
            << " mm): the surface starts small and may collapse (give landmarks, or click deeper inside)";
    warnings.push_back(message.str());
  }
  return warnings;
}

}  // namespace dynsub
