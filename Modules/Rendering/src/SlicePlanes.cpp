#include "dynsub/SlicePlanes.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkPointData.h>

#include "dynsub/Error.h"

namespace dynsub {

std::string orientationName(SliceOrientation orientation) {
  switch (orientation) {
    case SliceOrientation::Axial: return "axial";
    case SliceOrientation::Coronal: return "coronal";
    case SliceOrientation::Sagittal: return "sagittal";
  }
  return "";
}

namespace {

// Screen right and up in LPS (x to the patient's left, y posterior, z superior).
void anatomicalAxes(SliceOrientation orientation, Vector3& right, Vector3& up) {
  right = Vector3::UnitX();
  up = Vector3::UnitY();
  switch (orientation) {
    case SliceOrientation::Axial: right = Vector3(1, 0, 0); up = Vector3(0, -1, 0); break;
    case SliceOrientation::Coronal: right = Vector3(1, 0, 0); up = Vector3(0, 0, 1); break;
    case SliceOrientation::Sagittal: right = Vector3(0, 1, 0); up = Vector3(0, 0, 1); break;
  }
}

}  // namespace

SlicePlane anatomicalPlane(SliceOrientation orientation, const Vector3& point, double thickness) {
  SlicePlane plane;
  anatomicalAxes(orientation, plane.right, plane.up);
  plane.normal = plane.right.cross(plane.up);  // towards the viewer
  plane.origin = point;
  plane.thickness = thickness;
  return plane;
}

ImageSlices::ImageSlices(const Volume& volume) : ImageSlices(volume, false) {}

ImageSlices ImageSlices::borrowing(const Volume& volume) { return ImageSlices(volume, true); }

ImageSlices::ImageSlices(const Volume& volume, bool borrow) : geometry_(volume.geometry) {
  const auto& size = geometry_.size;
  if (volume.voxels.empty() || static_cast<long long>(volume.voxels.size()) != geometry_.voxelCount())
    throw Error("the image to display is empty or its buffer does not match its size");
  data_ = vtkSmartPointer<vtkImageData>::New();
  data_->SetDimensions(size[0], size[1], size[2]);
  data_->SetOrigin(0, 0, 0);
  data_->SetSpacing(1, 1, 1);
  vtkNew<vtkFloatArray> scalars;
  scalars->SetName("intensity");
  if (borrow) {
    // save = 1: VTK neither frees nor (the mappers only read) writes it.
    scalars->SetArray(const_cast<float*>(volume.voxels.data()), geometry_.voxelCount(), 1);
  } else {
    scalars->SetNumberOfTuples(geometry_.voxelCount());
    std::copy(volume.voxels.begin(), volume.voxels.end(), scalars->GetPointer(0));
  }
  data_->GetPointData()->SetScalars(scalars);
  voxels_ = scalars->GetPointer(0);

  indexToWorld_ = vtkSmartPointer<vtkMatrix4x4>::New();
  const Matrix3 linear = geometry_.direction * geometry_.spacing.asDiagonal();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) indexToWorld_->SetElement(r, c, linear(r, c));
    indexToWorld_->SetElement(r, 3, geometry_.origin[r]);
  }

  // Percentiles from every 7th voxel: plenty for a grey window, and cheap.
  std::vector<float> sample;
  sample.reserve(volume.voxels.size() / 7 + 1);
  for (std::size_t i = 0; i < volume.voxels.size(); i += 7)
    if (std::isfinite(volume.voxels[i])) sample.push_back(volume.voxels[i]);
  if (sample.empty()) throw Error("the image to display has no finite intensity");
  const GreyWindow whole = percentileWindow(sample);
  window_ = whole.window;
  level_ = whole.level;
}

ImageSlices::GreyWindow ImageSlices::percentileWindow(std::vector<float>& sample) {
  auto percentile = [&](double p) {
    auto nth = sample.begin() + static_cast<std::ptrdiff_t>(p * (sample.size() - 1));
    std::nth_element(sample.begin(), nth, sample.end());
    return static_cast<double>(*nth);
  };
  const double low = percentile(0.01), high = percentile(0.995);
  return {std::max(high - low, 1e-6), 0.5 * (low + high)};
}

ImageSlices::GreyWindow ImageSlices::windowAround(const MatrixX3& points, double margin) const {
  const auto [first, size] = boundingRegion(geometry_, points, margin);
  std::vector<float> sample;
  for (int k = first[2]; k < first[2] + size[2]; ++k)
    for (int j = first[1]; j < first[1] + size[1]; ++j)
      for (int i = first[0]; i < first[0] + size[0]; ++i) {
        const float v = voxels_[geometry_.offset(i, j, k)];
        if (std::isfinite(v)) sample.push_back(v);
      }
  if (sample.size() < 1000) return {window_, level_};
  // A tenth of the span more on each side, so that the darkest and brightest
  // tissues near the structure (CSF, white matter) keep their texture
  // instead of clipping to black and white.
  const GreyWindow span = percentileWindow(sample);
  return {1.2 * span.window, span.level};
}

vtkImageData* ImageSlices::data() const { return data_; }
vtkMatrix4x4* ImageSlices::indexToWorld() const { return indexToWorld_; }

int ImageSlices::axis(SliceOrientation orientation) const {
  Vector3 right, up;
  anatomicalAxes(orientation, right, up);
  const Vector3 normal = right.cross(up);
  int best = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(geometry_.direction.col(a).dot(normal)) > std::abs(geometry_.direction.col(best).dot(normal)))
      best = a;
  return best;
}

SlicePlane ImageSlices::plane(SliceOrientation orientation, int index) const {
  const int a = axis(orientation);
  SlicePlane plane;
  anatomicalAxes(orientation, plane.right, plane.up);
  const Vector3 wanted = plane.right.cross(plane.up);
  Vector3 normal = geometry_.direction.col(a).normalized();
  if (normal.dot(wanted) < 0) normal = -normal;
  plane.normal = normal;
  // Screen axes made orthogonal to an oblique slice's normal.
  plane.up = (plane.up - plane.up.dot(normal) * normal).normalized();
  plane.right = plane.up.cross(normal);
  Vector3 index3 = Vector3::Zero();
  index3[a] = index;
  plane.origin = geometry_.toPhysical(index3);
  plane.thickness = geometry_.spacing[a];
  return plane;
}

int ImageSlices::sliceThrough(SliceOrientation orientation, const Vector3& point) const {
  const int a = axis(orientation);
  const double index = geometry_.toIndex(point)[a];
  return std::clamp(static_cast<int>(std::lround(index)), 0, geometry_.size[a] - 1);
}

}  // namespace dynsub
