#pragma once
// One slice view (TVCG Figs 10-11): an image slice in grey, the surface's
// cross-section on that slice as a contour (vtkCutter; yellow on normal
// elements, green on special ones, as in the papers, or coloured by its
// distance to the image's edges), the landmarks that lie
// on the slice as red dots (the selected one cyan), and optionally range-data
// points near the slice. Orientation letters mark the screen edges.
// Everything is in LPS mm (SlicePlanes.h says how the image is placed).
#include <memory>
#include <string>
#include <vector>

#include "dynsub/FigureInputs.h"
#include "dynsub/SlicePlanes.h"

class vtkPolyData;
class vtkRenderer;

namespace dynsub {

class SliceView {
 public:
  explicit SliceView(SliceOrientation orientation);
  ~SliceView();
  SliceView(const SliceView&) = delete;
  SliceView& operator=(const SliceView&) = delete;

  vtkRenderer* renderer() const;
  SliceOrientation orientation() const;

  // Not owned; must outlive the view. nullptr: no image (planes are then set
  // with showPlane).
  void setImage(const ImageSlices* image);
  // The surface whose cross-section is drawn; the contour follows when the
  // polydata is modified (live fitting).
  void setSurface(vtkPolyData* surface);
  // The contour by its points' distance (style::colourByDistance; the
  // surface must carry its array) instead of by element type.
  void colourByDistance(const DistanceColours& colours);
  // Landmarks (#landmarks x 3, LPS mm); those within half a slice of the plane are drawn.
  void setLandmarks(const MatrixX3& landmarks, int selected = -1);
  // Range data drawn as small light grey dots where within half a slice, and
  // the points set aside from it as outliers as orange ones.
  void setDataPoints(const MatrixX3& points);
  void setOutliers(const MatrixX3& points);

  // Show the image's slice `index` (clamped), or any plane.
  void showSlice(int index);
  void showPlane(const SlicePlane& plane);
  const SlicePlane& plane() const;
  int sliceIndex() const;  // -1 without an image

  // A square of half side `halfSize` mm around `centre` fills the viewport.
  void frame(const Vector3& centre, double halfSize);
  // Text in the top-left corner; by default caption(), on two lines.
  void setTitle(const std::string& title);
  void setTitleVisible(bool visible);
  // The slice's orientation and index, and the coordinate it fixes, named in
  // the chosen system: "coronal 120/217  LPS y = 6.0 mm".
  std::string caption() const;
  void setCoordinates(FigureCoordinates coordinates);
  // Grey window and level of the image (by default the image's own).
  void setGreyWindow(double window, double level);

  // The point of the slice plane under a display position (pixels), and the
  // display position of a point (valid once the view has been rendered or framed).
  Vector3 pointAt(double displayX, double displayY) const;
  Eigen::Vector2d displayPosition(const Vector3& point) const;
  // Indices of the landmarks drawn on this slice.
  std::vector<int> landmarksOnSlice() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynsub
