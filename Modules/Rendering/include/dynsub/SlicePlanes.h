#pragma once
// Where the slice views cut: an image as VTK data placed in LPS mm, and the
// planes of axial, coronal and sagittal slices with their screen axes.
//
// VTK 9.1 draws image slices ignoring the image's direction matrix, so the
// image is handed to VTK in index space (origin 0, spacing 1) and its actor
// carries the index-to-LPS matrix (direction * diag(spacing), origin). Every
// other prop (surface, landmarks) is in LPS mm, and all of them line up.
//
// Screen axes follow the radiological convention of ITK-SNAP and 3D Slicer:
// axial and coronal views show the patient's right on the screen's left;
// axial has anterior up, coronal and sagittal superior up, sagittal anterior
// on the left.
#include <string>
#include <vector>

#include <vtkSmartPointer.h>

#include "dynsub/Volume.h"

class vtkImageData;
class vtkMatrix4x4;

namespace dynsub {

enum class SliceOrientation { Axial, Coronal, Sagittal };

std::string orientationName(SliceOrientation orientation);

// A slice: the plane through `origin` with unit `normal`, seen with `right`
// and `up` (unit, orthogonal, in the plane) as the screen axes; points within
// thickness / 2 of it lie on the slice.
struct SlicePlane {
  Vector3 origin = Vector3::Zero();
  Vector3 normal = Vector3::UnitZ();
  Vector3 right = Vector3::UnitX();
  Vector3 up = Vector3::UnitY();
  double thickness = 1.0;  // mm

  double distance(const Vector3& point) const { return (point - origin).dot(normal); }
};

// The anatomical screen axes of an orientation (LPS), and the plane with those
// axes through `point`, `thickness` thick (for scenes without an image).
SlicePlane anatomicalPlane(SliceOrientation orientation, const Vector3& point, double thickness);

class ImageSlices {
 public:
  // A copy of the volume's intensities.
  explicit ImageSlices(const Volume& volume);
  // The volume's own intensities, not copied: `volume` must outlive the
  // slices and stay unchanged. (Copying a whole MRI into fresh memory would
  // be a sizeable share of writing a segmentation's figures.)
  static ImageSlices borrowing(const Volume& volume);

  const ImageGeometry& geometry() const { return geometry_; }
  vtkImageData* data() const;          // index space: origin 0, spacing 1
  vtkMatrix4x4* indexToWorld() const;  // index -> LPS mm, for the image actors
  // Grey window and level: the 1st to 99.5th percentile of the intensities.
  double window() const { return window_; }
  double level() const { return level_; }
  // The same percentiles of the voxels in the box of `points` (LPS mm) and
  // `margin` mm around it (boundingRegion), widened by a tenth of their span
  // on each side: a structure's neighbourhood, whose tissues then span the
  // grey scale even where the whole image's bright fat or dark background
  // would squeeze them, without clipping. The whole image's window when the
  // box holds fewer than 1000 voxels.
  struct GreyWindow {
    double window = 1, level = 0.5;
  };
  GreyWindow windowAround(const MatrixX3& points, double margin) const;

  // The image axis (0 = i, 1 = j, 2 = k) closest to the orientation's normal.
  int axis(SliceOrientation orientation) const;
  int sliceCount(SliceOrientation orientation) const { return geometry_.size[axis(orientation)]; }
  // The slice of index `index` along axis(orientation): normal along that axis
  // (signed to face the viewer as anatomicalPlane does), screen axes the
  // anatomical ones made orthogonal to it, thickness one voxel.
  SlicePlane plane(SliceOrientation orientation, int index) const;
  // The slice index nearest a point, clamped to the image.
  int sliceThrough(SliceOrientation orientation, const Vector3& point) const;

 private:
  ImageSlices(const Volume& volume, bool borrow);
  // The 1st to 99.5th percentile of a sample (reordered).
  static GreyWindow percentileWindow(std::vector<float>& sample);

  ImageGeometry geometry_;
  const float* voxels_ = nullptr;  // the intensities (data_'s, or the borrowed volume's)
  vtkSmartPointer<vtkImageData> data_;
  vtkSmartPointer<vtkMatrix4x4> indexToWorld_;
  double window_ = 1, level_ = 0.5;
};

}  // namespace dynsub
