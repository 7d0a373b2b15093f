#include "dynsub/Figures.h"

#include <algorithm>
#include <cstdlib>
#include <memory>

#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkNew.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkWindowToImageFilter.h>

#include "dynsub/SceneStyle.h"
#include "dynsub/AtomicOutput.h"
#include "dynsub/ConvergencePlot.h"
#include "dynsub/Error.h"
#include "dynsub/SlicePlanes.h"
#include "dynsub/SliceView.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/SurfaceWriter.h"
#include "dynsub/SurfaceView.h"
#include "PngFile.h"

namespace dynsub {

namespace {

constexpr int kColumns = 5;
constexpr int kCell = 240;  // pixels per montage cell

void requireSurface(const FigureScene& scene) {
  if (!scene.surface || scene.surface->GetNumberOfPoints() == 0) throw Error("the figure has no surface to show");
}

MatrixX3 surfacePoints(vtkPolyData* surface) {
  MatrixX3 p(surface->GetNumberOfPoints(), 3);
  for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i) {
    double x[3];
    surface->GetPoint(i, x);
    p.row(i) << x[0], x[1], x[2];
  }
  return p;
}

}  // namespace

namespace {

// The figures drawn into a window, which is sized for them (its renderers
// are the caller's to have removed).
void drawSlices(const FigureScene& scene, vtkRenderWindow* window) {
  requireSurface(scene);
  const MatrixX3 points = surfacePoints(scene.surface);
  const Vector3 low = points.colwise().minCoeff().transpose(), high = points.colwise().maxCoeff().transpose();
  const Vector3 centre = 0.5 * (low + high);
  const ImageSlices* image = scene.image;
  if (image) {
    const Vector3 index = image->geometry().toIndex(centre);
    for (int a = 0; a < 3; ++a)
      if (index[a] < -0.5 || index[a] > image->geometry().size[a] - 0.5)
        throw Error("the surface lies outside the image: nothing to show on its slices");
  }
  const double diagonal = (high - low).norm();

  window->SetSize(kColumns * kCell, 3 * kCell);
  for (int row = 0; row < 3; ++row) {
    const auto orientation = static_cast<SliceOrientation>(row);
    // The surface's extent along the slice normal and across the view.
    SlicePlane axes = image ? image->plane(orientation, 0) : anatomicalPlane(orientation, centre, 0.015 * diagonal);
    const Eigen::VectorXd along = points * axes.normal;
    const Eigen::VectorXd across = points * axes.right, upward = points * axes.up;
    const double halfSize = 0.5 * 1.3 * std::max(across.maxCoeff() - across.minCoeff(), upward.maxCoeff() - upward.minCoeff()) + 3.0;
    for (int column = 0; column < kColumns; ++column) {
      SliceView view(orientation);
      view.setImage(image);
      view.setSurface(scene.surface);
      view.colourByEdgeDistance(scene.edgeDistances);
      // Interior slices, evenly spread: the end slices would only graze it.
      const double t = along.minCoeff() + (column + 1.0) / (kColumns + 1.0) * (along.maxCoeff() - along.minCoeff());
      const Vector3 through = centre + (t - centre.dot(axes.normal)) * axes.normal;
      if (image) {
        view.showSlice(image->sliceThrough(orientation, through));
      } else {
        view.showPlane(anatomicalPlane(orientation, through, axes.thickness));
      }
      view.setLandmarks(scene.landmarks);
      if (scene.dataPoints.rows() > 0) view.setDataPoints(scene.dataPoints);
      view.frame(centre, halfSize);
      // Row 0 at the top of the window.
      view.renderer()->SetViewport(double(column) / kColumns, (2.0 - row) / 3.0, (column + 1.0) / kColumns,
                                   (3.0 - row) / 3.0);
      window->AddRenderer(view.renderer());
    }
  }
}

void drawSurface(const FigureScene& scene, vtkRenderWindow* window) {
  requireSurface(scene);
  window->SetSize(800, 800);
  SurfaceView view;
  view.setSurface(scene.surface);
  view.colourByEdgeDistance(scene.edgeDistances);
  if (scene.controlMesh) view.setControlMesh(scene.controlMesh);
  view.setLandmarks(scene.landmarks);
  if (scene.dataPoints.rows() > 0) view.setDataPoints(scene.dataPoints);
  if (const ImageSlices* image = scene.image) {
    // Slices just behind the surface as seen by the camera (which looks from
    // the left, front and top): its right, back and bottom.
    double b[6];
    scene.surface->GetBounds(b);
    const Vector3 corner(b[0], b[3], b[4]);
    view.setImage(image);
    view.showSlices(image->sliceThrough(SliceOrientation::Axial, corner),
                    image->sliceThrough(SliceOrientation::Coronal, corner),
                    image->sliceThrough(SliceOrientation::Sagittal, corner));
  }
  view.resetCamera();
  window->AddRenderer(view.renderer());
}

void drawConvergence(const ConvergenceHistory& history, vtkRenderWindow* window) {
  window->SetSize(900, 500);
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1, 1, 1);
  vtkNew<vtkContextActor> actor;
  actor->GetScene()->AddItem(convergenceChart(history));
  renderer->AddActor(actor);
  window->AddRenderer(renderer);
}

}  // namespace

vtkSmartPointer<vtkRenderWindow> slicesFigure(const FigureScene& scene) {
  auto window = style::offScreenWindow(kColumns * kCell, 3 * kCell);
  drawSlices(scene, window);
  return window;
}

vtkSmartPointer<vtkRenderWindow> surfaceFigure(const FigureScene& scene) {
  auto window = style::offScreenWindow(800, 800);
  drawSurface(scene, window);
  return window;
}

vtkSmartPointer<vtkRenderWindow> convergenceFigure(const ConvergenceHistory& history) {
  auto window = style::offScreenWindow(900, 500);
  drawConvergence(history, window);
  return window;
}

void writePng(vtkRenderWindow* window, const std::string& path) {
  AtomicOutput output(path);
  window->Render();
  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(window);
  capture->ReadFrontBufferOff();
  capture->Update();
  vtkImageData* image = capture->GetOutput();
  int size[3];
  image->GetDimensions(size);
  if (image->GetScalarType() != VTK_UNSIGNED_CHAR)
    throw writeFailure(path, "internal: the window's capture is not 8-bit");
  // PngFile.h says why not vtkPNGWriter.
  writePngFile(output.temporaryPath(), size[0], size[1], image->GetNumberOfScalarComponents(),
               static_cast<const unsigned char*>(image->GetScalarPointer()));
  output.commit();
}

void writeFigures(const FigureInputs& inputs, const FigureFiles& files) {
  const vtkSmartPointer<vtkPolyData> surface =
      inputs.surface ? toPolyData(*inputs.surface) : readSurfacePolyData(inputs.surfaceFile);
  if (inputs.edgeDistances.size() > 0) {
    if (inputs.edgeDistances.size() != surface->GetNumberOfPoints())
      throw Error("internal: the edge distances are not one per point of the figure's surface");
    addPointData(surface, kEdgeDistanceScalars, inputs.edgeDistances);
  }
  FigureScene scene;
  scene.surface = surface;
  scene.edgeDistances = surface->GetPointData()->GetArray(kEdgeDistanceScalars) != nullptr;
  scene.landmarks = inputs.landmarks;
  scene.dataPoints = inputs.dataPoints;
  std::unique_ptr<ImageSlices> slices;
  if (inputs.image) {
    slices = std::make_unique<ImageSlices>(ImageSlices::borrowing(*inputs.image));  // the image outlives the figures
    scene.image = slices.get();
  }
  vtkSmartPointer<vtkPolyData> wireframe;
  if (inputs.controlMesh) {
    wireframe = controlMeshWireframe(*inputs.controlMesh);
    scene.controlMesh = wireframe;
  }
  if (!files.convergence.empty() && !inputs.history) throw Error("internal: a convergence figure without a history");
  // NB: one window for all three: creating a window (choosing its GLX
  // framebuffer configuration, starting its context) costs a sizeable share
  // of the figures' time. Each figure's renderers leave it before the next's
  // come.
  const vtkSmartPointer<vtkRenderWindow> window = style::offScreenWindow(kColumns * kCell, 3 * kCell);
  auto draw = [&](const std::string& path, const auto& figure) {
    if (path.empty()) return;
    while (vtkRenderer* previous = window->GetRenderers()->GetFirstRenderer()) window->RemoveRenderer(previous);
    figure();
    writePng(window, path);
  };
  draw(files.slices, [&] { drawSlices(scene, window); });
  draw(files.surface3d, [&] { drawSurface(scene, window); });
  draw(files.convergence, [&] { drawConvergence(*inputs.history, window); });
}

}  // namespace dynsub
