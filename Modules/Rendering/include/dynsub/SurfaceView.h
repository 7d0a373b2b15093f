#pragma once
// The 3D view: the limit surface lit and coloured by element type (yellow
// normal, green special elements, as in the papers) or by a distance of each
// point (a segmentation's to the image's edges, a fit's to its scan),
// optionally translucent;
// the control mesh as a wireframe; landmarks as red dots; range data as white
// dots; and the image's three slice planes through a point. LPS mm.
#include <memory>
#include <vector>

#include "dynsub/FigureInputs.h"
#include "dynsub/SlicePlanes.h"

class vtkPolyData;
class vtkRenderer;

namespace dynsub {

class ControlMesh;

// The control mesh's edges as lines (one line per edge, in Topology's edge
// order), LPS mm; a creased mesh's lines carry colours (cell scalars), its
// creases orange-red, the rest the wireframe's blue.
vtkSmartPointer<vtkPolyData> controlMeshWireframe(const ControlMesh& mesh);

class SurfaceView {
 public:
  SurfaceView();
  ~SurfaceView();
  SurfaceView(const SurfaceView&) = delete;
  SurfaceView& operator=(const SurfaceView&) = delete;

  vtkRenderer* renderer() const;

  void setSurface(vtkPolyData* surface);  // followed when modified
  void setOpacity(double opacity);        // 1 opaque
  // By each point's distance (style::colourByDistance; the surface must
  // carry its array), with a colour bar, instead of by element type.
  void colourByDistance(const DistanceColours& colours);
  void setControlMesh(vtkPolyData* wireframe);  // nullptr hides it
  void setLandmarks(const MatrixX3& landmarks, int selected = -1);  // #landmarks x 3, LPS mm
  void setDataPoints(const MatrixX3& points);
  void setOutliers(const MatrixX3& points);  // range data set aside, drawn apart from it
  // The three slice planes of `image` (not owned) at the given slice indices
  // (axial, coronal, sagittal); nullptr hides them.
  void setImage(const ImageSlices* image);
  void showSlices(int axial, int coronal, int sagittal);

  // Looks at the surface's bounds from the front, left and above (the
  // patient's left-anterior-superior side), the whole surface in view.
  void resetCamera();
  // The same view of the box [low, high] (mm).
  void frame(const Vector3& low, const Vector3& high);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynsub
