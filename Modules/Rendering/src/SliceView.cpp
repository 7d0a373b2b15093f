#include "dynsub/SliceView.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <iomanip>
#include <vector>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCutter.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkNonMergingPointLocator.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPolyDataAlgorithm.h>
#include <vtkImageProperty.h>
#include <vtkImageSlice.h>
#include <vtkImageSliceMapper.h>
#include <vtkNew.h>
#include <vtkPlane.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include "dynsub/SceneStyle.h"

namespace dynsub {

namespace {

// The polygons of a surface that reach a plane (their points on both sides
// of it, or on it), in their order and with their cell data, on the input's
// points: all the cutter below can cut. Otherwise a figure's fifteen views
// would each cut the whole surface (49 152 triangles for a segmentation);
// the cut is the same, segment for segment. A surface with other cells than
// polygons is passed whole.
class PolygonsAtPlane : public vtkPolyDataAlgorithm {
 public:
  static PolygonsAtPlane* New();
  vtkTypeMacro(PolygonsAtPlane, vtkPolyDataAlgorithm);

  void SetPlane(vtkPlane* plane) {
    plane_ = plane;
    Modified();
  }
  // The plane moves without this filter being told (its own modified time).
  vtkMTimeType GetMTime() override {
    const vtkMTimeType own = vtkPolyDataAlgorithm::GetMTime();
    return plane_ ? std::max(own, plane_->GetMTime()) : own;
  }

 protected:
  int RequestData(vtkInformation*, vtkInformationVector** inputs, vtkInformationVector* outputs) override {
    vtkPolyData* input = vtkPolyData::GetData(inputs[0]);
    vtkPolyData* output = vtkPolyData::GetData(outputs);
    if (!plane_ || input->GetNumberOfVerts() + input->GetNumberOfLines() + input->GetNumberOfStrips() > 0) {
      output->ShallowCopy(input);
      return 1;
    }
    output->SetPoints(input->GetPoints());
    output->GetPointData()->PassData(input->GetPointData());
    const vtkIdType pointCount = input->GetNumberOfPoints();
    std::vector<double> side(static_cast<std::size_t>(pointCount));
    for (vtkIdType p = 0; p < pointCount; ++p) side[p] = plane_->EvaluateFunction(input->GetPoint(p));
    vtkCellData* cellsIn = input->GetCellData();
    vtkCellData* cellsOut = output->GetCellData();
    cellsOut->CopyAllocate(cellsIn);
    vtkNew<vtkCellArray> kept;
    vtkCellArray* polygons = input->GetPolys();
    vtkIdType count = 0;
    const vtkIdType* ids = nullptr;
    polygons->InitTraversal();
    for (vtkIdType cell = 0; polygons->GetNextCell(count, ids); ++cell) {
      double low = side[ids[0]], high = low;
      for (vtkIdType k = 1; k < count; ++k) low = std::min(low, side[ids[k]]), high = std::max(high, side[ids[k]]);
      if (low > 0.0 || high < 0.0) continue;
      cellsOut->CopyData(cellsIn, cell, kept->InsertNextCell(count, ids));
    }
    output->SetPolys(kept);
    return 1;
  }

 private:
  vtkSmartPointer<vtkPlane> plane_;
};
vtkStandardNewMacro(PolygonsAtPlane);

}  // namespace

struct SliceView::Impl {
  SliceOrientation orientation;
  const ImageSlices* image = nullptr;
  SlicePlane plane;
  int index = -1;
  MatrixX3 landmarks;
  int selected = -1;
  MatrixX3 dataPoints;
  MatrixX3 outliers;

  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkImageSliceMapper> imageMapper;
  vtkNew<vtkImageSlice> imageActor;
  vtkNew<vtkPlane> cutPlane;
  vtkNew<PolygonsAtPlane> atPlane;
  vtkNew<vtkCutter> cutter;
  vtkNew<vtkPolyDataMapper> contourMapper;
  vtkNew<vtkActor> contourActor;
  vtkNew<vtkPolyData> landmarkPoints;
  vtkNew<vtkActor> landmarkActor;
  vtkNew<vtkPolyData> dataOnSlice;
  vtkNew<vtkActor> dataActor;
  vtkNew<vtkPolyData> outliersOnSlice;
  vtkNew<vtkActor> outlierActor;
  vtkNew<vtkTextActor> title;
  vtkNew<vtkTextActor> edgeLetters[4];  // left, right, top, bottom
  bool customTitle = false;
  FigureCoordinates coordinates = FigureCoordinates::Lps;

  explicit Impl(SliceOrientation o) : orientation(o) {
    renderer->SetBackground(0, 0, 0);
    imageActor->SetMapper(imageMapper);
    imageActor->VisibilityOff();
    renderer->AddViewProp(imageActor);

    atPlane->SetPlane(cutPlane);
    cutter->SetInputConnection(atPlane->GetOutputPort());
    cutter->SetCutFunction(cutPlane);
    // The contour's points are not merged, and the locator has one bin:
    // a merging locator allocates bins for the whole surface (and the kernel
    // clears their fresh pages) in each of the slices figure's 15 views. Only
    // the lines are drawn, so merging their ends would change nothing.
    vtkNew<vtkNonMergingPointLocator> locator;
    locator->AutomaticOff();
    locator->SetDivisions(1, 1, 1);
    cutter->SetLocator(locator);
    contourMapper->SetInputConnection(cutter->GetOutputPort());
    style::colourByElementType(contourMapper);
    contourActor->SetMapper(contourMapper);
    contourActor->GetProperty()->SetLineWidth(2.0);
    contourActor->GetProperty()->LightingOff();
    contourActor->VisibilityOff();
    renderer->AddActor(contourActor);

    style::showLandmarks(renderer, landmarkPoints, landmarkActor);
    style::showDataPoints(renderer, dataOnSlice, dataActor);
    style::showOutliers(renderer, outliersOnSlice, outlierActor);

    style::cornerText(title, 0.02, 0.97, style::Corner::TopLeft);
    renderer->AddActor2D(title);
    const double at[4][2] = {{0.02, 0.5}, {0.98, 0.5}, {0.5, 0.98}, {0.5, 0.02}};
    const style::Corner corners[4] = {style::Corner::Left, style::Corner::Right, style::Corner::Top,
                                      style::Corner::Bottom};
    for (int e = 0; e < 4; ++e) {
      style::cornerText(edgeLetters[e], at[e][0], at[e][1], corners[e]);
      edgeLetters[e]->GetTextProperty()->SetColor(0.9, 0.75, 0.2);
      renderer->AddActor2D(edgeLetters[e]);
    }
    plane = anatomicalPlane(orientation, Vector3::Zero(), 1.0);
  }

  // Overlays sit a little towards the viewer so that the image slice, drawn
  // exactly on the plane, never hides them.
  Vector3 overlayShift() const { return 0.05 * plane.thickness * plane.normal; }

  // Rows of `points` within half a slice thickness of the plane.
  std::vector<int> onSlice(const MatrixX3& points) const {
    std::vector<int> rows;
    for (int r = 0; r < static_cast<int>(points.rows()); ++r)
      if (std::abs(plane.distance(points.row(r).transpose())) <= 0.5 * plane.thickness) rows.push_back(r);
    return rows;
  }

  void update() {
    cutPlane->SetOrigin(plane.origin.x(), plane.origin.y(), plane.origin.z());
    cutPlane->SetNormal(plane.normal.x(), plane.normal.y(), plane.normal.z());
    const Vector3 shift = overlayShift();
    for (vtkActor* overlay : {contourActor.Get(), landmarkActor.Get(), dataActor.Get(), outlierActor.Get()})
      overlay->SetPosition(shift.x(), shift.y(), shift.z());

    landmarkPoints->ShallowCopy(style::dots(landmarks, onSlice(landmarks), selected));
    dataOnSlice->ShallowCopy(style::dots(dataPoints, onSlice(dataPoints)));
    outliersOnSlice->ShallowCopy(style::dots(outliers, onSlice(outliers)));

    // Edge letters: the anatomical direction each screen edge points to.
    const Vector3 towards[4] = {-plane.right, plane.right, plane.up, -plane.up};
    for (int e = 0; e < 4; ++e) edgeLetters[e]->SetInput(style::anatomicalLetter(towards[e]).c_str());
    if (!customTitle) title->SetInput((slice() + "\n" + coordinate()).c_str());
    placeCamera();
  }

  std::string slice() const {
    std::ostringstream text;
    text << orientationName(orientation);
    if (image) text << " " << index + 1 << "/" << image->sliceCount(orientation);
    return text.str();
  }

  // The coordinate the slice fixes (x for sagittal, y coronal, z axial).
  std::string coordinate() const {
    const int a = orientation == SliceOrientation::Axial ? 2 : orientation == SliceOrientation::Coronal ? 1 : 0;
    const double value = coordinates == FigureCoordinates::Ras && a < 2 ? -plane.origin[a] : plane.origin[a];
    std::ostringstream text;
    text << std::fixed << std::setprecision(1) << coordinatesName(coordinates) << " " << "xyz"[a] << " = "
         << (std::abs(value) < 0.05 ? 0.0 : value) << " mm";
    return text.str();
  }

  void placeCamera() {
    vtkCamera* camera = renderer->GetActiveCamera();
    double focal[3];
    camera->GetFocalPoint(focal);
    // Keep the framed centre, moved onto the plane.
    Vector3 centre(focal[0], focal[1], focal[2]);
    centre -= plane.distance(centre) * plane.normal;
    const Vector3 eye = centre + style::kCameraDistance * plane.normal;
    camera->ParallelProjectionOn();
    camera->SetFocalPoint(centre.data());
    camera->SetPosition(eye.data());
    camera->SetViewUp(plane.up.data());
    camera->SetClippingRange(0.5 * style::kCameraDistance, 1.5 * style::kCameraDistance);
  }
};

SliceView::SliceView(SliceOrientation orientation) : impl_(std::make_unique<Impl>(orientation)) {}
SliceView::~SliceView() = default;

vtkRenderer* SliceView::renderer() const { return impl_->renderer; }
SliceOrientation SliceView::orientation() const { return impl_->orientation; }

void SliceView::setImage(const ImageSlices* image) {
  impl_->image = image;
  if (!image) {
    impl_->imageActor->VisibilityOff();
    impl_->index = -1;
    return;
  }
  impl_->imageMapper->SetInputData(image->data());
  impl_->imageMapper->SetOrientation(image->axis(impl_->orientation));
  impl_->imageActor->SetUserMatrix(image->indexToWorld());
  setGreyWindow(image->window(), image->level());
  impl_->imageActor->GetProperty()->SetInterpolationTypeToNearest();
  impl_->imageActor->VisibilityOn();
  showSlice(image->sliceCount(impl_->orientation) / 2);
}

void SliceView::setSurface(vtkPolyData* surface) {
  impl_->atPlane->SetInputData(surface);
  impl_->contourActor->SetVisibility(surface != nullptr);
}

void SliceView::colourByDistance(const DistanceColours& colours) {
  style::colourByDistance(impl_->contourMapper, colours);
}

void SliceView::setLandmarks(const MatrixX3& landmarks, int selected) {
  impl_->landmarks = landmarks;
  impl_->selected = selected;
  impl_->update();
}

void SliceView::setDataPoints(const MatrixX3& points) {
  impl_->dataPoints = points;
  impl_->update();
}

void SliceView::setOutliers(const MatrixX3& points) {
  impl_->outliers = points;
  impl_->update();
}

void SliceView::showSlice(int index) {
  if (!impl_->image) return;
  const int count = impl_->image->sliceCount(impl_->orientation);
  impl_->index = std::clamp(index, 0, count - 1);
  impl_->imageMapper->SetSliceNumber(impl_->index);
  impl_->plane = impl_->image->plane(impl_->orientation, impl_->index);
  impl_->update();
}

void SliceView::showPlane(const SlicePlane& plane) {
  impl_->plane = plane;
  impl_->update();
}

const SlicePlane& SliceView::plane() const { return impl_->plane; }
int SliceView::sliceIndex() const { return impl_->index; }

void SliceView::frame(const Vector3& centre, double halfSize) {
  vtkCamera* camera = impl_->renderer->GetActiveCamera();
  camera->SetFocalPoint(centre.data());
  camera->SetParallelScale(halfSize);
  impl_->placeCamera();
}

void SliceView::setTitle(const std::string& title) {
  impl_->customTitle = true;
  impl_->title->SetInput(title.c_str());
}

void SliceView::setTitleVisible(bool visible) { impl_->title->SetVisibility(visible); }

std::string SliceView::caption() const { return impl_->slice() + "  " + impl_->coordinate(); }

void SliceView::setCoordinates(FigureCoordinates coordinates) {
  impl_->coordinates = coordinates;
  impl_->update();
}

void SliceView::setGreyWindow(double window, double level) {
  impl_->imageActor->GetProperty()->SetColorWindow(window);
  impl_->imageActor->GetProperty()->SetColorLevel(level);
}

Vector3 SliceView::pointAt(double displayX, double displayY) const {
  const Vector3 p = style::worldAt(impl_->renderer, displayX, displayY, 0.0);
  return p - impl_->plane.distance(p) * impl_->plane.normal;
}

Eigen::Vector2d SliceView::displayPosition(const Vector3& point) const {
  return style::displayAt(impl_->renderer, point).head<2>();
}

std::vector<int> SliceView::landmarksOnSlice() const { return impl_->onSlice(impl_->landmarks); }

}  // namespace dynsub
