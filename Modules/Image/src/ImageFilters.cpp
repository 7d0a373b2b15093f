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

namespace {

// A box of samples, i fastest.
struct Block {
  std::array<int, 3> size{0, 0, 0};
  std::vector<double> values;
  double& at(int i, int j, int k) { return values[i + static_cast<std::size_t>(size[0]) * (j + size[1] * k)]; }
};

// `in` correlated with `kernel` (2 r + 1 taps) along `axis`: the box loses r
// samples at both ends of that axis.
Block along(const Block& in, int axis, const std::vector<double>& kernel) {
  const int r = static_cast<int>(kernel.size() / 2);
  Block out;
  out.size = in.size;
  out.size[axis] -= 2 * r;
  out.values.assign(static_cast<std::size_t>(out.size[0]) * out.size[1] * out.size[2], 0.0);
  const std::size_t stride = axis == 0 ? 1 : axis == 1 ? in.size[0] : static_cast<std::size_t>(in.size[0]) * in.size[1];
  for (int k = 0; k < out.size[2]; ++k)
    for (int j = 0; j < out.size[1]; ++j)
      for (int i = 0; i < out.size[0]; ++i) {
        const double* first = &in.values[i + static_cast<std::size_t>(in.size[0]) * (j + in.size[1] * k)];
        double sum = 0;
        for (std::size_t t = 0; t < kernel.size(); ++t) sum += kernel[t] * first[t * stride];
        out.at(i, j, k) = sum;
      }
  return out;
}

}  // namespace

std::vector<Vector3> smoothedGradientIn(const Volume& image, double sigma, const std::array<int, 3>& first,
                                        const std::array<int, 3>& size) {
  const ImageGeometry& g = image.geometry;
  // Per axis, the sampled Gaussian to 4 sigma (summing to 1) and its
  // derivative (giving slope 1 on a ramp of 1 per mm).
  std::array<std::vector<double>, 3> smooth, slope;
  std::array<int, 3> radius{};
  for (int a = 0; a < 3; ++a) {
    radius[a] = std::max(1, static_cast<int>(std::ceil(4 * sigma / g.spacing[a])));
    double total = 0, moment = 0;
    for (int t = -radius[a]; t <= radius[a]; ++t) {
      const double x = t * g.spacing[a];
      const double weight = std::exp(-x * x / (2 * sigma * sigma));
      smooth[a].push_back(weight);
      slope[a].push_back(x * weight);
      total += weight;
      moment += x * x * weight;
    }
    for (double& w : smooth[a]) w /= total;
    for (double& w : slope[a]) w /= moment;
  }
  Block in;
  for (int a = 0; a < 3; ++a) in.size[a] = size[a] + 2 * radius[a];
  in.values.resize(static_cast<std::size_t>(in.size[0]) * in.size[1] * in.size[2]);
  for (int k = 0; k < in.size[2]; ++k)
    for (int j = 0; j < in.size[1]; ++j)
      for (int i = 0; i < in.size[0]; ++i) {
        const int x = std::clamp(first[0] - radius[0] + i, 0, g.size[0] - 1);
        const int y = std::clamp(first[1] - radius[1] + j, 0, g.size[1] - 1);
        const int z = std::clamp(first[2] - radius[2] + k, 0, g.size[2] - 1);
        in.at(i, j, k) = image.at(x, y, z);
      }
  const Block smoothZ = along(in, 2, smooth[2]);
  const Block dx = along(along(smoothZ, 1, smooth[1]), 0, slope[0]);
  const Block dy = along(along(smoothZ, 0, smooth[0]), 1, slope[1]);
  const Block dz = along(along(along(in, 2, slope[2]), 1, smooth[1]), 0, smooth[0]);
  // Derivatives along the grid's axes to LPS: a gradient is covariant.
  const Matrix3 toPhysical = g.direction.transpose().inverse();
  std::vector<Vector3> gradient(dx.values.size());
  for (std::size_t v = 0; v < gradient.size(); ++v)
    gradient[v] = toPhysical * Vector3(dx.values[v], dy.values[v], dz.values[v]);
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
