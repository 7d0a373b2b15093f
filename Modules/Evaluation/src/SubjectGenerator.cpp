#include "dynsub/SubjectGenerator.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <vector>

#include "dynsub/Error.h"
#include "dynsub/ImageFilters.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/Percentile.h"
#include "dynsub/TextFields.h"

namespace dynsub {
namespace {

// Draws from the standard's 64-bit Mersenne Twister, whose output the
// standard fixes, through transforms of its own: the library's distributions
// may differ between implementations.
class Draw {
 public:
  explicit Draw(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double low, double high) { return low + (high - low) * uniform(); }
  double normal() {  // Box and Muller's transform, one of the pair
    const double radius = std::sqrt(-2.0 * std::log(1.0 - uniform()));
    return radius * std::cos(2.0 * M_PI * uniform());
  }
  Vector3 inBall(double radius) {
    for (;;) {
      const Vector3 v(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
      if (v.squaredNorm() <= 1) return radius * v;
    }
  }

 private:
  std::mt19937_64 engine_;
};

// Cubic B-spline weights of the four nodes around t (node floor(t) - 1 first).
std::array<double, 4> cubicWeights(double t, int& first) {
  const double f = std::floor(t), u = t - f;
  first = static_cast<int>(f) - 1;
  const double v = 1 - u;
  return {v * v * v / 6, (3 * u * u * u - 6 * u * u + 4) / 6, (-3 * u * u * u + 3 * u * u + 3 * u + 1) / 6,
          u * u * u / 6};
}

// A vector field on a grid's continuous index, a cubic B-spline over nodes
// `spacingMm` apart along the grid's axes, covering the grid.
class BSplineField {
 public:
  BSplineField(const ImageGeometry& grid, double spacingMm) {
    for (int a = 0; a < 3; ++a) {
      step_[a] = spacingMm / grid.spacing[a];  // voxels between nodes
      nodes_[a] = static_cast<int>(std::floor((grid.size[a] - 1) / step_[a])) + 4;
    }
    values_.assign(static_cast<std::size_t>(nodes_[0]) * nodes_[1] * nodes_[2], Vector3::Zero());
  }
  std::size_t nodeCount() const { return values_.size(); }
  Vector3& node(std::size_t n) { return values_[n]; }

  Vector3 at(const Vector3& index) const {
    std::array<std::array<double, 4>, 3> w;
    std::array<int, 3> first;
    for (int a = 0; a < 3; ++a) w[a] = cubicWeights(index[a] / step_[a], first[a]);
    Vector3 sum = Vector3::Zero();
    for (int c = 0; c < 4; ++c) {
      const int nk = std::clamp(first[2] + c + 1, 0, nodes_[2] - 1);
      for (int b = 0; b < 4; ++b) {
        const int nj = std::clamp(first[1] + b + 1, 0, nodes_[1] - 1);
        const double wjk = w[1][b] * w[2][c];
        for (int a = 0; a < 4; ++a) {
          const int ni = std::clamp(first[0] + a + 1, 0, nodes_[0] - 1);
          sum += (w[0][a] * wjk) * values_[ni + static_cast<std::size_t>(nodes_[0]) * (nj + nodes_[1] * nk)];
        }
      }
    }
    return sum;
  }

 private:
  std::array<double, 3> step_{};
  std::array<int, 3> nodes_{};
  std::vector<Vector3> values_;
};

// The map from the subject's grid to the source's physical space:
// p -> centre + linear (p + warp(p) - centre) + translation.
struct SubjectMap {
  Matrix3 linear = Matrix3::Identity();
  Vector3 centre = Vector3::Zero(), translation = Vector3::Zero();
  BSplineField warp;
  const ImageGeometry& grid;

  Vector3 sourcePoint(const Vector3& index) const {
    const Vector3 p = grid.toPhysical(index) + warp.at(index);
    return centre + linear * (p - centre) + translation;
  }
};

Matrix3 rotation(const Vector3& radians) {
  return (Eigen::AngleAxisd(radians.z(), Vector3::UnitZ()) * Eigen::AngleAxisd(radians.y(), Vector3::UnitY()) *
          Eigen::AngleAxisd(radians.x(), Vector3::UnitX()))
      .toRotationMatrix();
}

// The smallest Jacobian determinant of the map, by differences over one
// voxel at every fourth voxel along each axis.
double smallestJacobian(const SubjectMap& map, const ImageGeometry& grid) {
  const double gridVolume = (grid.direction * grid.spacing.asDiagonal()).determinant();
  std::vector<double> smallest(static_cast<std::size_t>(grid.size[2]), 1e300);
  parallelFor(grid.size[2], 2, [&](Eigen::Index index) {
    const int k = static_cast<int>(index);
    if (k % 4 || k + 1 >= grid.size[2]) return;
    for (int j = 0; j + 1 < grid.size[1]; j += 4) {
      for (int i = 0; i + 1 < grid.size[0]; i += 4) {
        const Vector3 x(i, j, k);
        const Vector3 p = map.sourcePoint(x);
        Matrix3 d;
        for (int a = 0; a < 3; ++a) d.col(a) = map.sourcePoint(x + Vector3::Unit(a)) - p;
        smallest[k] = std::min(smallest[k], d.determinant() / gridVolume);
      }
    }
  });
  return *std::min_element(smallest.begin(), smallest.end());
}

// The image averaged over `factor` voxels along `axis` (thick slices: each
// slice's signal is the mean over its thickness).
Volume thickSlices(const Volume& image, int axis, int factor) {
  Volume thick;
  thick.geometry = image.geometry;
  thick.geometry.size[axis] = image.geometry.size[axis] / factor;
  thick.geometry.spacing[axis] *= factor;
  thick.geometry.origin += image.geometry.direction.col(axis) * image.geometry.spacing[axis] * (factor - 1) / 2.0;
  thick.voxels.assign(static_cast<std::size_t>(thick.geometry.voxelCount()), 0.0f);
  const ImageGeometry& g = thick.geometry;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        double sum = 0;
        for (int s = 0; s < factor; ++s) {
          std::array<int, 3> at{i, j, k};
          at[axis] = at[axis] * factor + s;
          sum += image.at(at[0], at[1], at[2]);
        }
        thick.voxels[g.offset(i, j, k)] = static_cast<float>(sum / factor);
      }
  return thick;
}

// The two thresholds between a head's three tissue classes (dark, grey and
// white in a T1 image): one-dimensional k-means over a 512-bin histogram of
// `head`, started at its 10th, 50th and 90th percentiles.
std::array<double, 2> tissueThresholds(const std::vector<float>& head, const std::string& source) {
  const auto [lowest, highest] = std::minmax_element(head.begin(), head.end());
  const double low = *lowest, high = *highest;
  std::array<double, 3> centre{percentile(head, 0.1), percentile(head, 0.5), percentile(head, 0.9)};
  if (!(high > low)) throw Error(source, "the head has one intensity: no tissue classes");
  constexpr int kBins = 512;
  std::vector<double> count(kBins, 0);
  const double width = (high - low) / kBins;
  for (const float v : head) ++count[std::min(kBins - 1, static_cast<int>((v - low) / width))];
  for (int iteration = 0; iteration < 200; ++iteration) {
    std::array<double, 3> sum{}, weight{};
    for (int b = 0; b < kBins; ++b) {
      const double value = low + (b + 0.5) * width;
      int nearest = 0;
      for (int c = 1; c < 3; ++c)
        if (std::abs(value - centre[c]) < std::abs(value - centre[nearest])) nearest = c;
      sum[nearest] += count[b] * value;
      weight[nearest] += count[b];
    }
    std::array<double, 3> next = centre;
    for (int c = 0; c < 3; ++c)
      if (weight[c] > 0) next[c] = sum[c] / weight[c];
    if (next == centre) break;
    centre = next;
  }
  return {0.5 * (centre[0] + centre[1]), 0.5 * (centre[1] + centre[2])};
}

// The labels of a label map in increasing order; synthesized subjects need
// them to be whole numbers in 0..65535, as label maps are written.
std::vector<int> labelValues(const Volume& labels, const std::string& source) {
  std::vector<char> seen(65536, 0);
  for (const float l : labels.voxels) {
    if (!(l >= 0 && l <= 65535 && l == std::floor(l)))
      throw Error(source,
                  "a synthesized subject needs labels that are whole numbers in 0..65535, found " + std::to_string(l));
    seen[static_cast<int>(l)] = 1;
  }
  std::vector<int> values;
  for (int l = 1; l < 65536; ++l)
    if (seen[l]) values.push_back(l);
  return values;
}

// A synthesized subject's intensities, in units of the source's bright end:
// a mean and a texture (the sigma of white noise before the blur) per
// tissue class and per label.
struct Contrast {
  struct Tissue {
    double mean = 0, texture = 0;
  };
  bool t2 = false;
  Tissue dark, grey, white;
  std::vector<Tissue> label;  // by label value
};

Contrast drawContrast(Draw& draw, const SubjectSettings& settings, const std::vector<int>& labels) {
  Contrast c;
  c.t2 = draw.uniform() < settings.t2Fraction;
  // T1: CSF dark, white matter bright. T2: the order reversed, with white
  // matter above air and CSF the brightest.
  c.dark.mean = c.t2 ? draw.uniform(0.85, 1.0) : draw.uniform(0.08, 0.22);
  c.grey.mean = c.t2 ? draw.uniform(0.5, 0.62) : draw.uniform(0.42, 0.55);
  c.white.mean = c.t2 ? draw.uniform(0.25, 0.35) : draw.uniform(0.72, 0.88);
  for (Contrast::Tissue* t : {&c.dark, &c.grey, &c.white}) t->texture = draw.uniform(0.01, 0.03);
  c.label.resize(labels.empty() ? 0 : labels.back() + 1);
  for (const int l : labels)
    c.label[l] = {c.grey.mean + draw.uniform(-settings.labelSpread, settings.labelSpread), draw.uniform(0.01, 0.03)};
  return c;
}

}  // namespace

void setSubjectSetting(SubjectSettings& s, const std::string& key, const std::string& value) {
  auto number = [&](const std::string& text) {
    double v = 0;
    if (!parseNumber(text, v) || !std::isfinite(v))
      throw Error("subject settings", key + " must be a number, got '" + value + "'");
    return v;
  };
  auto range = [&](std::array<double, 2>& r) {
    const auto comma = value.find(',');
    r[0] = number(value.substr(0, comma));
    r[1] = comma == std::string::npos ? r[0] : number(value.substr(comma + 1));
  };
  const std::pair<const char*, double SubjectSettings::*> scalars[] = {
      {"rotation_degrees", &SubjectSettings::rotationDegrees},
      {"scale_spread", &SubjectSettings::scaleSpread},
      {"shear_spread", &SubjectSettings::shearSpread},
      {"translation_mm", &SubjectSettings::translationMm},
      {"warp_spacing_mm", &SubjectSettings::warpSpacingMm},
      {"warp_mm", &SubjectSettings::warpMm},
      {"gamma_spread", &SubjectSettings::gammaSpread},
      {"bias_spread", &SubjectSettings::biasSpread},
      {"source_snr", &SubjectSettings::sourceSnr},
      {"thick_fraction", &SubjectSettings::thickFraction},
      {"thick_mm", &SubjectSettings::thickMm},
      {"t2_fraction", &SubjectSettings::t2Fraction},
      {"label_spread", &SubjectSettings::labelSpread}};
  for (const auto& [name, member] : scalars) {
    if (key == name) {
      s.*member = number(value);
      return;
    }
  }
  if (key == "mode") {
    if (value != "realistic" && value != "synthesized")
      throw Error("subject settings", "mode must be 'realistic' or 'synthesized', got '" + value + "'");
    s.synthesized = value == "synthesized";
    return;
  }
  if (key == "structure_labels") {
    s.structureLabels.clear();
    for (const std::string& item : splitItems(value, ',')) {
      const double label = number(item);
      if (label < 1 || label > 65535 || label != std::floor(label))
        throw Error("subject settings", "structure_labels must be whole numbers in 1..65535, got '" + item + "'");
      s.structureLabels.push_back(static_cast<int>(label));
    }
    return;
  }
  if (key == "thick_axis") {
    const double axis = number(value);
    if (axis != -1 && axis != 0 && axis != 1 && axis != 2)
      throw Error("subject settings",
                  "thick_axis must be 0, 1 or 2 (an index axis), or -1 to draw it, got '" + value + "'");
    s.thickAxis = static_cast<int>(axis);
    return;
  }
  if (key == "blur_mm") return range(s.blurMm);
  if (key == "snr") return range(s.snr);
  throw Error("subject settings", "unknown setting '" + key + "'");
}

void checkSubjectSettings(const SubjectSettings& s) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw Error("subject settings", what);
  };
  require(s.rotationDegrees >= 0 && s.rotationDegrees <= 45, "rotation_degrees must be in 0..45");
  require(s.scaleSpread >= 0 && s.scaleSpread <= 0.3, "scale_spread must be in 0..0.3");
  require(s.shearSpread >= 0 && s.shearSpread <= 0.2, "shear_spread must be in 0..0.2");
  require(s.translationMm >= 0 && s.translationMm <= 50, "translation_mm must be in 0..50");
  require(s.warpSpacingMm >= 5 && s.warpSpacingMm <= 200, "warp_spacing_mm must be in 5..200");
  require(s.warpMm >= 0 && s.warpMm < 0.4 * s.warpSpacingMm,
          "warp_mm must be at least 0 and under 0.4 x warp_spacing_mm, or the deformation may fold");
  require(s.gammaSpread >= 0 && s.gammaSpread <= 1, "gamma_spread must be in 0..1");
  require(s.biasSpread >= 0 && s.biasSpread < 1, "bias_spread must be in 0..1 (below 1)");
  require(s.blurMm[0] >= 0 && s.blurMm[0] <= s.blurMm[1] && s.blurMm[1] <= 5,
          "blur_mm must be LOW,HIGH with 0 <= LOW <= HIGH <= 5");
  require(s.snr[0] > 0 && s.snr[0] <= s.snr[1] && s.snr[1] <= 1000,
          "snr must be LOW,HIGH with 0 < LOW <= HIGH <= 1000");
  require(s.sourceSnr > 0, "source_snr must be positive");
  // Settings of synthesized subjects' intensities, which a realistic one
  // takes from its source.
  require(s.synthesized || (s.structureLabels.empty() && s.t2Fraction == 0),
          "structure_labels and t2_fraction are for synthesized subjects (mode=synthesized): a realistic subject "
          "keeps the source's intensities");
  // A realistic subject keeps the source's own noise: it cannot be cleaner.
  std::ostringstream sourceSnr;
  sourceSnr << s.sourceSnr;
  require(s.synthesized || s.snr[1] <= s.sourceSnr,
          "snr's HIGH must be at most source_snr (" + sourceSnr.str() +
              "): a realistic subject keeps the source image's own noise, so it is never cleaner than the source");
  require(s.thickFraction >= 0 && s.thickFraction <= 1, "thick_fraction must be in 0..1");
  require(s.thickMm > 0 && s.thickMm <= 10, "thick_mm must be over 0 and at most 10");
  require(s.t2Fraction >= 0 && s.t2Fraction <= 1, "t2_fraction must be in 0..1");
  require(s.labelSpread >= 0 && s.labelSpread <= 0.1,
          "label_spread must be in 0..0.1 (grey structures would reach white matter's intensities)");
}

Subject makeSubject(const Volume& image, const Volume& labels, const SubjectSettings& settings, std::uint64_t seed,
                    const SubjectSources& sources) {
  checkSubjectSettings(settings);
  const ImageGeometry& grid = image.geometry;
  Draw draw(seed);
  Subject subject;
  subject.draw.seed = seed;

  // The anatomy's map: affine about the image's centre, then the warp.
  SubjectMap map{Matrix3::Identity(),
                 grid.toPhysical(0.5 * Vector3(grid.size[0] - 1, grid.size[1] - 1, grid.size[2] - 1)), Vector3::Zero(),
                 BSplineField(grid, settings.warpSpacingMm), grid};
  const double maxAngle = settings.rotationDegrees * M_PI / 180;
  const Vector3 angles(draw.uniform(-maxAngle, maxAngle), draw.uniform(-maxAngle, maxAngle),
                       draw.uniform(-maxAngle, maxAngle));
  Matrix3 scaleShear = Matrix3::Identity();
  for (int a = 0; a < 3; ++a) scaleShear(a, a) = 1 + draw.uniform(-settings.scaleSpread, settings.scaleSpread);
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b) scaleShear(a, b) = draw.uniform(-settings.shearSpread, settings.shearSpread);
  map.linear = rotation(angles) * scaleShear;
  for (int a = 0; a < 3; ++a) map.translation[a] = draw.uniform(-settings.translationMm, settings.translationMm);
  for (std::size_t n = 0; n < map.warp.nodeCount(); ++n) map.warp.node(n) = draw.inBall(settings.warpMm);
  subject.draw.smallestJacobian = smallestJacobian(map, grid);

  // The anatomy moved: the image by trilinear interpolation (0 outside the
  // source), the labels by the nearest label.
  Volume anatomy{grid, std::vector<float>(image.voxels.size(), 0.0f)};
  subject.labels = {grid, std::vector<float>(image.voxels.size(), 0.0f)};
  const Matrix3 toSourceIndex = image.geometry.indexFromPhysical();
  const Matrix3 toLabelIndex = labels.geometry.indexFromPhysical();
  parallelFor(grid.size[2], 2, [&](Eigen::Index index) {
    const int k = static_cast<int>(index);
    for (int j = 0; j < grid.size[1]; ++j) {
      for (int i = 0; i < grid.size[0]; ++i) {
        const Vector3 p = map.sourcePoint(Vector3(i, j, k));
        const long long at = grid.offset(i, j, k);
        const Vector3 sourceIndex = toSourceIndex * (p - image.geometry.origin);
        if (image.geometry.spans(sourceIndex)) anatomy.voxels[at] = static_cast<float>(image.interpolate(sourceIndex));
        const Vector3 labelIndex = toLabelIndex * (p - labels.geometry.origin);
        const int li = static_cast<int>(std::lround(labelIndex.x())),
                  lj = static_cast<int>(std::lround(labelIndex.y())),
                  lk = static_cast<int>(std::lround(labelIndex.z()));
        if (labels.geometry.contains(li, lj, lk)) subject.labels.voxels[at] = labels.at(li, lj, lk);
      }
    }
  });

  std::vector<float> positive;
  positive.reserve(anatomy.voxels.size());
  for (const float v : anatomy.voxels)
    if (v > 0) positive.push_back(v);
  const float bright = percentile(positive, 0.995);
  if (!(bright > 0)) throw Error(sources.image, "no positive intensities: no head to make a subject of");
  std::optional<double> whiteMatter;  // known exactly for synthesized subjects
  if (!settings.synthesized) {
    // Contrast: the head's intensities scaled to 0..1 by its bright end,
    // raised to gamma, and scaled back.
    subject.draw.gamma = std::exp(draw.uniform(-settings.gammaSpread, settings.gammaSpread));
    for (float& v : anatomy.voxels)
      v = v > 0 ? static_cast<float>(bright * std::pow(v / bright, subject.draw.gamma)) : 0.0f;
  } else {
    // Each voxel's class: its label if it has one; else air below a tenth
    // of the bright end, or the tissue class of the moved source intensity.
    std::vector<float> head;
    for (const float v : positive)
      if (v > 0.1f * bright) head.push_back(v);
    const std::array<double, 2> threshold = tissueThresholds(head, sources.image);
    const std::vector<int> present = labelValues(labels, sources.labels);
    std::vector<char> structure(present.empty() ? 0 : present.back() + 1, settings.structureLabels.empty());
    for (const int l : settings.structureLabels) {
      if (!std::binary_search(present.begin(), present.end(), l))
        throw Error(sources.labels, "no voxel has the label " + std::to_string(l) + ", which structure_labels names");
      structure[l] = 1;
    }
    const Contrast contrast = drawContrast(draw, settings, present);
    subject.draw.contrast = contrast.t2 ? "t2" : "t1";
    for (std::size_t v = 0; v < anatomy.voxels.size(); ++v) {
      const int label = static_cast<int>(subject.labels.voxels[v]);
      const double source = anatomy.voxels[v];
      const Contrast::Tissue* tissue = nullptr;
      if (label > 0 && structure[label])
        tissue = &contrast.label[label];
      else if (source > 0.1 * bright)
        tissue = source < threshold[0] ? &contrast.dark : source < threshold[1] ? &contrast.grey : &contrast.white;
      anatomy.voxels[v] =
          tissue ? static_cast<float>(bright * std::max(0.0, tissue->mean + tissue->texture * draw.normal())) : 0.0f;
    }
    whiteMatter = bright * contrast.white.mean;
  }

  // A bias field: smooth, within 1 +- biasSpread (a B-spline over nodes 80
  // mm apart never leaves its nodes' range).
  BSplineField bias(grid, 80);
  const double logBias = std::log1p(settings.biasSpread);
  for (std::size_t n = 0; n < bias.nodeCount(); ++n) bias.node(n) = Vector3(draw.uniform(-logBias, logBias), 0, 0);
  parallelFor(grid.size[2], 2, [&](Eigen::Index index) {
    const int k = static_cast<int>(index);
    for (int j = 0; j < grid.size[1]; ++j)
      for (int i = 0; i < grid.size[0]; ++i)
        anatomy.voxels[grid.offset(i, j, k)] *= static_cast<float>(std::exp(bias.at(Vector3(i, j, k)).x()));
  });

  // The scanner's blur, then thick slices for some subjects.
  subject.draw.blurMm = draw.uniform(settings.blurMm[0], settings.blurMm[1]);
  Volume acquired = subject.draw.blurMm > 0 ? gaussianSmoothed(anatomy, subject.draw.blurMm) : anatomy;
  anatomy = Volume();
  if (draw.uniform() < settings.thickFraction) {
    const int drawn = std::min(2, static_cast<int>(draw.uniform() * 3));
    const int axis = settings.thickAxis >= 0 ? settings.thickAxis : drawn;
    const int factor = static_cast<int>(std::lround(settings.thickMm / grid.spacing[axis]));
    if (factor >= 2 && grid.size[axis] >= 2 * factor) {
      subject.draw.thickAxis = axis;
      acquired = thickSlices(acquired, axis, factor);
    }
  }

  // Rician noise at the drawn SNR of white matter. A realistic subject's
  // white matter is taken as the median of the head's brightest quarter
  // (above a tenth of its bright end), where T1 images have it, and its
  // noise adds to the source's own; a synthesized subject's is its drawn
  // mean, and it has no noise of its own.
  if (whiteMatter) {
    subject.draw.whiteMatter = *whiteMatter;
  } else {
    std::vector<float> head;
    for (const float v : acquired.voxels)
      if (v > 0.1f * bright) head.push_back(v);
    const float upper = percentile(head, 0.75);
    std::vector<float> brightest;
    for (const float v : head)
      if (v >= upper) brightest.push_back(v);
    subject.draw.whiteMatter = percentile(brightest, 0.5);
  }
  subject.draw.snr = draw.uniform(settings.snr[0], settings.snr[1]);
  const double total = subject.draw.whiteMatter / subject.draw.snr;
  const double own = whiteMatter ? 0.0 : subject.draw.whiteMatter / settings.sourceSnr;
  subject.draw.noiseSigma = std::sqrt(std::max(0.0, total * total - own * own));
  for (float& v : acquired.voxels) {
    const double real = v + subject.draw.noiseSigma * draw.normal(),
                 imaginary = subject.draw.noiseSigma * draw.normal();
    v = static_cast<float>(std::hypot(real, imaginary));
  }
  subject.image = std::move(acquired);
  return subject;
}

std::string subjectRecord(const SubjectDraw& d) {
  std::ostringstream out;
  out.precision(6);
  out << "{\"seed\": " << d.seed << ", \"contrast\": \"" << d.contrast << "\", \"gamma\": " << d.gamma
      << ", \"blur_mm\": " << d.blurMm << ", \"snr\": " << d.snr << ", \"noise_sigma\": " << d.noiseSigma
      << ", \"white_matter\": " << d.whiteMatter
      << ", \"thick_axis\": " << (d.thickAxis ? std::to_string(*d.thickAxis) : std::string("null"))
      << ", \"smallest_jacobian\": " << d.smallestJacobian << "}";
  return out.str();
}

}  // namespace dynsub
