#include "dynsub/ClickAppearance.h"

#include <algorithm>
#include <cmath>

#include "dynsub/Error.h"
#include "RobustStatistics.h"

namespace dynsub {
namespace {

constexpr double kOnSlice = 0.25;  // voxels, as SliceEnds.cpp
constexpr int kLeastSamples = 8;   // per side

double interquartileRange(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() * 3 / 4] - values[values.size() / 4];
}

}  // namespace

std::optional<ClickAppearance> ClickAppearance::learn(const Volume& image, const std::vector<Landmark>& landmarks,
                                                      int axis, double offset) {
  if (axis < 0 || axis > 2) throw Error("internal: the clicks' slice axis must be 0, 1 or 2");
  if (!(offset > 0) || !std::isfinite(offset)) throw Error("the appearance's sampling offset must be > 0 mm");
  const ImageGeometry& g = image.geometry;
  const Vector3 along = g.direction.col(axis).normalized();
  std::vector<Vector3> index;
  for (const Landmark& l : landmarks) index.push_back(g.toIndex(l.position));
  std::vector<double> inside, outside;
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    Vector3 centre = Vector3::Zero();
    int onSlice = 0;
    for (std::size_t j = 0; j < landmarks.size(); ++j)
      if (std::abs(index[j](axis) - index[i](axis)) <= kOnSlice) centre += landmarks[j].position, ++onSlice;
    if (onSlice < 3) continue;
    centre /= onSlice;
    Vector3 outward = landmarks[i].position - centre;
    outward -= outward.dot(along) * along;  // within the slice
    if (!(outward.norm() > 1e-6 * g.spacing.minCoeff())) continue;
    outward.normalize();
    for (const double t : {offset, 2 * offset}) {
      const Vector3 in = g.toIndex(landmarks[i].position - t * outward);
      const Vector3 out = g.toIndex(landmarks[i].position + t * outward);
      if (g.spans(in)) inside.push_back(image.interpolate(in));
      if (g.spans(out)) outside.push_back(image.interpolate(out));
    }
  }
  if (inside.size() < kLeastSamples || outside.size() < kLeastSamples) return std::nullopt;

  ClickAppearance a;
  a.insideSamples_ = static_cast<int>(inside.size());
  a.outsideSamples_ = static_cast<int>(outside.size());
  double low = inside.front(), high = inside.front();
  for (const auto* side : {&inside, &outside})
    for (double v : *side) low = std::min(low, v), high = std::max(high, v);
  // The kernel's width: half the narrower side's spread (its interquartile
  // range as a standard deviation), so that two classes a spread apart stay
  // apart. Chosen on the evaluation's tuning split, whose mean Dice hardly
  // depends on it (by less than 0.005 from half to twice this). The floor
  // (a thousandth of the intensities' scale) keeps a class of one repeated
  // value a narrow bump.
  const double spread = std::min(interquartileRange(inside), interquartileRange(outside)) / 1.349;
  const double width = std::max(0.5 * spread, 1e-3 * (1.0 + std::max(std::abs(low), std::abs(high))));
  // At least two table entries per kernel width, so that no class falls
  // between entries (256 to 4096 of them).
  const double extent = high - low + 6 * width;
  const int entries = static_cast<int>(std::clamp(std::ceil(2 * extent / width) + 1, 256.0, 4096.0));
  a.first_ = low - 3 * width;
  a.step_ = extent / (entries - 1);
  a.table_.resize(entries);
  std::vector<double> pIn(entries), pOut(entries);
  double sumIn = 0, sumOut = 0;
  for (int k = 0; k < entries; ++k) {
    const double x = a.first_ + k * a.step_;
    for (double v : inside) pIn[k] += std::exp(-0.5 * (x - v) * (x - v) / (width * width));
    for (double v : outside) pOut[k] += std::exp(-0.5 * (x - v) * (x - v) / (width * width));
    pIn[k] /= static_cast<double>(inside.size());
    pOut[k] /= static_cast<double>(outside.size());
    // Far from every sample both densities underflow to 0: no score there.
    const double total = pIn[k] + pOut[k];
    a.table_[k] = total > 0 ? (pIn[k] - pOut[k]) / total : 0.0;
    sumIn += pIn[k], sumOut += pOut[k];
  }
  if (!(sumIn > 0) || !(sumOut > 0)) return std::nullopt;  // cannot happen with the table's resolution
  double difference = 0;
  for (int k = 0; k < entries; ++k) difference += std::abs(pIn[k] / sumIn - pOut[k] / sumOut);
  a.separation_ = 0.5 * difference;
  for (int k = 0; k + 1 < entries; ++k)
    a.largestSlope_ = std::max(a.largestSlope_, std::abs(a.table_[k + 1] - a.table_[k]) / a.step_);
  return a;
}

double ClickAppearance::score(double intensity) const {
  if (!std::isfinite(intensity)) return 0.0;
  // Linear between table entries; the end entries beyond the table.
  const int last = static_cast<int>(table_.size()) - 1;
  const double at = std::clamp((intensity - first_) / step_, 0.0, static_cast<double>(last));
  const int k = std::min(static_cast<int>(at), last - 1);
  const double f = at - k;
  return (1 - f) * table_[k] + f * table_[k + 1];
}

EndPressure::EndPressure(const Volume& region, ClickAppearance appearance, const std::vector<Landmark>& landmarks,
                         int axis, double strength, std::optional<End> before, std::optional<End> after)
    : region_(region), appearance_(std::move(appearance)), before_(before), after_(after), strength_(strength) {
  if (axis < 0 || axis > 2) throw Error("internal: the clicks' slice axis must be 0, 1 or 2");
  if (landmarks.empty()) throw Error("internal: a pressure beyond the clicked slices needs clicks");
  if (!(strength >= 0) || !std::isfinite(strength)) throw Error("the pressure beyond the end slices must be >= 0");
  toIndex_ = region.geometry.indexFromPhysical();
  along_ = region.geometry.direction.col(axis).normalized();
  first_ = last_ = along_.dot(landmarks.front().position);
  for (const Landmark& l : landmarks) {
    first_ = std::min(first_, along_.dot(l.position));
    last_ = std::max(last_, along_.dot(l.position));
  }
  slopeBound_ = strength_ * appearance_.largestSlope() * steepGradient(region);
}

Eigen::VectorXd EndPressure::pressuresAt(const MatrixX3& points) const {
  const ImageGeometry& g = region_.geometry;
  Eigen::VectorXd pressures = Eigen::VectorXd::Zero(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Vector3 x = points.row(i).transpose();
    const double t = along_.dot(x);
    if (t >= first_ && t <= last_) continue;  // the clicked span
    const std::optional<End>& end = t < first_ ? before_ : after_;
    if (!end || std::max(first_ - t, t - last_) > end->reach) continue;
    Vector3 across = x - end->centre;
    across -= across.dot(along_) * along_;
    if (across.norm() > end->radius) continue;
    const Vector3 index = toIndex_ * (x - g.origin);
    // Outside the region the image is unknown: no push.
    if (g.spans(index)) pressures(i) = strength_ * appearance_.score(region_.interpolate(index));
  }
  return pressures;
}

}  // namespace dynsub
