#include "dynsub/ImageFilters.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "BridgeGeometry.h"
#include "dynsub/ParallelFor.h"

namespace dynsub {

std::vector<Vector3> smoothedGradient(const Volume& image, double sigma) {
  const std::vector<float> raw =
      itkbridge::recursiveGaussianGradient(toBridge(image.geometry), image.voxels, sigma);
  std::vector<Vector3> gradient(image.voxels.size());
  for (std::size_t v = 0; v < gradient.size(); ++v) gradient[v] = Vector3(raw[3 * v], raw[3 * v + 1], raw[3 * v + 2]);
  return gradient;
}

Volume gaussianSmoothed(const Volume& image, double sigma) {
  return {image.geometry, itkbridge::recursiveGaussian(toBridge(image.geometry), image.voxels, sigma)};
}

namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();  // no feature on the line
constexpr float kNoneStored = std::numeric_limits<float>::infinity();

// One line of the squared distance transform: f(q) <- min over p of
// (s (q - p))^2 + f(p), for the n samples f[0], f[stride], ... (kNone where
// there is nothing), by the lower envelope of the parabolas rooted at the
// samples (Felzenszwalb and Huttenlocher, "Distance transforms of sampled
// functions", Theory of Computing 8, 2012). `line`, `root` and `from` are
// scratch of n, n and n + 1 entries.
void squaredDistanceAlong(float* f, long long stride, int n, double s, std::vector<double>& line,
                          std::vector<int>& root, std::vector<double>& from) {
  for (int q = 0; q < n; ++q) line[q] = f[q * stride];
  int k = -1;  // the envelope's last parabola
  for (int q = 0; q < n; ++q) {
    if (line[q] == kNone) continue;
    const double xq = q * s;
    double meet = -kNone;
    while (k >= 0) {
      const double xp = root[k] * s;
      meet = ((line[q] + xq * xq) - (line[root[k]] + xp * xp)) / (2.0 * (xq - xp));
      if (meet > from[k]) break;
      --k;  // the new parabola hides this one wholly
    }
    ++k;
    root[k] = q;
    from[k] = k == 0 ? -kNone : meet;
    from[k + 1] = kNone;
  }
  if (k < 0) return;  // nothing on this line: it stays kNone
  int at = 0;
  for (int q = 0; q < n; ++q) {
    const double xq = q * s;
    while (from[at + 1] < xq) ++at;
    const double d = xq - root[at] * s;
    f[q * stride] = static_cast<float>(d * d + line[root[at]]);
  }
}

}  // namespace

std::vector<float> distanceTo(const Mask& mask) {
  const ImageGeometry& g = mask.geometry;
  const long long count = g.voxelCount();
  // Squared distances are kept in floats between the passes (each line is
  // worked in doubles): on 1 mm and 0.5 mm grids floats hold them exactly,
  // elsewhere they round as ITK's did; half the memory of doubles, and the
  // distances are taken in place.
  std::vector<float> squared(count);
  for (long long v = 0; v < count; ++v) squared[v] = mask.voxels[v] ? 0.0f : kNoneStored;
  const long long stride[3] = {1, g.size[0], static_cast<long long>(g.size[0]) * g.size[1]};
  // One pass per axis, each over every line along that axis; a pass's lines
  // are independent, so they are shared between the cores.
  for (int axis = 0; axis < 3; ++axis) {
    const int n = g.size[axis];
    const int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;  // the other two axes
    const long long lines = static_cast<long long>(g.size[a]) * g.size[b];
    // A thread for every 32 768 voxels at most (about 0.4 ms of a pass: a
    // segmentation region of 36 x 62 x 57 voxels takes both cores).
    const Eigen::Index parts = std::clamp<Eigen::Index>(lines * n / 32768, 1, hardwareThreads());
    const long long chunk = (lines + parts - 1) / parts;
    parallelFor(parts, parts, [&](Eigen::Index part) {
      std::vector<double> line(n), from(n + 1);
      std::vector<int> root(n);
      for (long long l = part * chunk; l < std::min(lines, (part + 1) * chunk); ++l) {
        const long long first = (l % g.size[a]) * stride[a] + (l / g.size[a]) * stride[b];
        squaredDistanceAlong(squared.data() + first, stride[axis], n, g.spacing(axis), line, root, from);
      }
    });
  }
  for (float& d : squared) d = std::sqrt(d);
  return squared;
}

}  // namespace dynsub
