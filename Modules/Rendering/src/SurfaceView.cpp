#include "dynsub/SurfaceView.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkImageProperty.h>
#include <vtkImageSlice.h>
#include <vtkImageSliceMapper.h>
#include <vtkMath.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkUnsignedCharArray.h>

#include "dynsub/SceneStyle.h"
#include "dynsub/ControlMesh.h"

namespace dynsub {

vtkSmartPointer<vtkPolyData> controlMeshWireframe(const ControlMesh& mesh) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  const MatrixX3 p = mesh.points();
  for (Eigen::Index i = 0; i < p.rows(); ++i) points->InsertNextPoint(p(i, 0), p(i, 1), p(i, 2));
  vtkNew<vtkCellArray> lines;
  const Topology& topology = mesh.topology();
  // A creased mesh's edges carry their colours: creases stand out from the rest.
  vtkNew<vtkUnsignedCharArray> colours;
  colours->SetNumberOfComponents(3);
  colours->SetName("Colors");
  std::array<unsigned char, 3> wire{};
  for (int c = 0; c < 3; ++c) wire[c] = static_cast<unsigned char>(std::lround(255.0 * style::kWireframe[c]));
  for (int e = 0; e < topology.edgeCount(); ++e) {
    const auto [a, b] = topology.edgeVertices(e);
    const vtkIdType ids[2] = {a, b};
    lines->InsertNextCell(2, ids);
    if (topology.hasCreases()) {
      const bool creased = topology.edgeSharpness(e) > 0.0 && !topology.isBoundaryEdge(e);
      colours->InsertNextTypedTuple(creased ? style::kCrease.data() : wire.data());
    }
  }
  auto wireframe = vtkSmartPointer<vtkPolyData>::New();
  wireframe->SetPoints(points);
  wireframe->SetLines(lines);
  if (topology.hasCreases()) wireframe->GetCellData()->SetScalars(colours);
  return wireframe;
}

struct SurfaceView::Impl {
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkPolyDataMapper> surfaceMapper;
  vtkNew<vtkActor> surfaceActor;
  vtkNew<vtkPolyDataMapper> wireMapper;
  vtkNew<vtkActor> wireActor;
  vtkNew<vtkPolyData> landmarkPoints;
  vtkNew<vtkActor> landmarkActor;
  vtkNew<vtkPolyData> dataPoints;
  vtkNew<vtkActor> dataActor;
  vtkNew<vtkPolyData> outliers;
  vtkNew<vtkActor> outlierActor;
  const ImageSlices* image = nullptr;
  vtkNew<vtkImageSliceMapper> sliceMappers[3];
  vtkNew<vtkImageSlice> sliceActors[3];
  vtkSmartPointer<vtkScalarBarActor> distanceBar;

  Impl() {
    renderer->SetBackground(0.1, 0.1, 0.12);
    style::colourByElementType(surfaceMapper);
    surfaceActor->SetMapper(surfaceMapper);
    surfaceActor->GetProperty()->SetSpecular(0.2);
    surfaceActor->GetProperty()->SetSpecularPower(20);
    surfaceActor->VisibilityOff();
    renderer->AddActor(surfaceActor);

    wireActor->SetMapper(wireMapper);
    wireActor->GetProperty()->SetColor(style::kWireframe[0], style::kWireframe[1], style::kWireframe[2]);
    wireActor->GetProperty()->LightingOff();
    wireActor->VisibilityOff();
    renderer->AddActor(wireActor);

    style::showLandmarks(renderer, landmarkPoints, landmarkActor);
    style::showDataPoints(renderer, dataPoints, dataActor);
    style::showOutliers(renderer, outliers, outlierActor);

    for (int s = 0; s < 3; ++s) {
      sliceActors[s]->SetMapper(sliceMappers[s]);
      sliceActors[s]->VisibilityOff();
      renderer->AddViewProp(sliceActors[s]);
    }
  }
};

SurfaceView::SurfaceView() : impl_(std::make_unique<Impl>()) {}
SurfaceView::~SurfaceView() = default;

vtkRenderer* SurfaceView::renderer() const { return impl_->renderer; }

void SurfaceView::setSurface(vtkPolyData* surface) {
  impl_->surfaceMapper->SetInputData(surface);
  impl_->surfaceActor->SetVisibility(surface != nullptr);
}

void SurfaceView::colourByDistance(const DistanceColours& colours) {
  style::colourByDistance(impl_->surfaceMapper, colours);
  if (impl_->distanceBar) impl_->renderer->RemoveActor2D(impl_->distanceBar);
  impl_->distanceBar = style::distanceBar(colours);
  impl_->renderer->AddActor2D(impl_->distanceBar);
}

void SurfaceView::setOpacity(double opacity) { impl_->surfaceActor->GetProperty()->SetOpacity(opacity); }

void SurfaceView::setControlMesh(vtkPolyData* wireframe) {
  impl_->wireMapper->SetInputData(wireframe);
  impl_->wireActor->SetVisibility(wireframe != nullptr);
}

void SurfaceView::setLandmarks(const MatrixX3& landmarks, int selected) {
  impl_->landmarkPoints->ShallowCopy(style::dots(landmarks, style::allRows(landmarks), selected));
}

void SurfaceView::setDataPoints(const MatrixX3& points) {
  impl_->dataPoints->ShallowCopy(style::dots(points, style::allRows(points)));
}

void SurfaceView::setOutliers(const MatrixX3& points) {
  impl_->outliers->ShallowCopy(style::dots(points, style::allRows(points)));
}

void SurfaceView::setImage(const ImageSlices* image) {
  impl_->image = image;
  for (int s = 0; s < 3; ++s) {
    impl_->sliceActors[s]->SetVisibility(image != nullptr);
    if (!image) continue;
    const auto orientation = static_cast<SliceOrientation>(s);
    impl_->sliceMappers[s]->SetInputData(image->data());
    impl_->sliceMappers[s]->SetOrientation(image->axis(orientation));
    impl_->sliceMappers[s]->SetSliceNumber(image->sliceCount(orientation) / 2);
    impl_->sliceActors[s]->SetUserMatrix(image->indexToWorld());
    impl_->sliceActors[s]->GetProperty()->SetColorWindow(image->window());
    impl_->sliceActors[s]->GetProperty()->SetColorLevel(image->level());
  }
}

void SurfaceView::showSlices(int axial, int coronal, int sagittal) {
  if (!impl_->image) return;
  const int index[3] = {axial, coronal, sagittal};
  for (int s = 0; s < 3; ++s) {
    const auto orientation = static_cast<SliceOrientation>(s);
    impl_->sliceMappers[s]->SetSliceNumber(std::clamp(index[s], 0, impl_->image->sliceCount(orientation) - 1));
  }
}

void SurfaceView::resetCamera() {
  double bounds[6];
  vtkPolyData* surface = vtkPolyData::SafeDownCast(impl_->surfaceMapper->GetInput());
  if (surface && surface->GetNumberOfPoints() > 0) {
    surface->GetBounds(bounds);
  } else {
    impl_->renderer->ComputeVisiblePropBounds(bounds);
  }
  frame(Vector3(bounds[0], bounds[2], bounds[4]), Vector3(bounds[1], bounds[3], bounds[5]));
}

void SurfaceView::frame(const Vector3& low, const Vector3& high) {
  const Vector3 centre = 0.5 * (low + high);
  const double radius = std::max(0.5 * (high - low).norm(), 1e-3);
  // From the patient's left (+x), front (-y) and above (+z).
  const Vector3 direction = Vector3(1.0, -1.2, 0.8).normalized();
  vtkCamera* camera = impl_->renderer->GetActiveCamera();
  camera->ParallelProjectionOff();
  camera->SetViewAngle(30);
  camera->SetFocalPoint(centre.data());
  const Vector3 eye = centre + direction * (radius / std::sin(vtkMath::RadiansFromDegrees(15.0)));
  camera->SetPosition(eye.data());
  camera->SetViewUp(0, 0, 1);
  impl_->renderer->ResetCameraClippingRange();
}

}  // namespace dynsub
