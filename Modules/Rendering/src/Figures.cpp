#include "dynsub/Figures.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vtkActor.h>
#include <vtkAnnotatedCubeActor.h>
#include <vtkAxis.h>
#include <vtkCamera.h>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkGL2PSExporter.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPropCollection.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <memory>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "PngFile.h"
#include "dynsub/AtomicOutput.h"
#include "dynsub/ConvergencePlot.h"
#include "dynsub/Error.h"
#include "dynsub/SceneStyle.h"
#include "dynsub/SlicePlanes.h"
#include "dynsub/SliceView.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/SurfaceView.h"
#include "dynsub/SurfaceWriter.h"

namespace dynsub {

namespace {

constexpr int kColumns = 5;
constexpr int kCell = 240;    // pixels per montage cell's image
constexpr int kCaption = 18;  // pixels of each cell's caption strip, above its image
constexpr int kLegend = 26;   // pixels of the slices figure's legend strip, at the bottom
constexpr int kSlicesWidth = kColumns * kCell;
constexpr int kSlicesHeight = 3 * (kCell + kCaption) + kLegend;
constexpr int kCaptionFont = 12;

// A renderer over a pixel rectangle of a window of the given size, with a
// black background.
vtkSmartPointer<vtkRenderer> strip(int x0, int y0, int x1, int y1, int width, int height) {
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  renderer->SetBackground(0, 0, 0);
  renderer->SetViewport(double(x0) / width, double(y0) / height, double(x1) / width, double(y1) / height);
  return renderer;
}

// Text at the left of a strip, vertically centred, in a colour.
vtkTextActor* addText(vtkRenderer* renderer, const std::string& text, double x, const std::array<double, 3>& colour) {
  vtkNew<vtkTextActor> actor;
  style::cornerText(actor, x, 0.5, style::Corner::Left, kCaptionFont);
  actor->GetTextProperty()->SetColor(colour.data());
  actor->SetInput(text.c_str());
  renderer->AddActor2D(actor);
  return actor;
}

// The landmarks' colour (style::kLandmark, 8-bit) for text.
std::array<double, 3> landmarkColour() {
  const auto& c = style::kLandmark;
  return {c[0] / 255.0, c[1] / 255.0, c[2] / 255.0};
}

// What the slices' colours mean, in one strip: the contour's colours, the
// landmarks and the range data as drawn, and the coordinates the captions use.
void addLegend(const FigureScene& scene, vtkRenderWindow* window) {
  std::vector<std::pair<std::string, std::array<double, 3>>> items;
  if (scene.distances) {
    std::ostringstream near, far;
    near << std::setprecision(3) << "contour ";
    if (scene.distances->near > 0.0) {
      near << "within " << scene.distances->near << " mm of " << scene.distances->on;
    } else {
      near << "on " << scene.distances->on;
    }
    items.push_back({near.str(), style::kNearColour});
    far << std::setprecision(3) << "contour " << scene.distances->far << " mm or more from " << scene.distances->from;
    items.push_back({far.str(), style::kFarColour});
  } else {
    items.push_back({"contour on a normal element", style::kNormalElement});
    items.push_back({"contour on a special element", style::kSpecialElement});
  }
  if (scene.landmarks.rows() > 0) items.push_back({"landmarks on the slice", landmarkColour()});
  if (scene.dataPoints.rows() > 0) items.push_back({"range data near the slice", style::kDataPoint});
  if (scene.outliers.rows() > 0) items.push_back({"outliers set aside, near the slice", style::kOutlierPoint});
  items.push_back({"coordinates: " + coordinatesName(scene.coordinates) + " mm", {1, 1, 1}});
  auto legend = strip(0, 0, kSlicesWidth, kLegend, kSlicesWidth, kSlicesHeight);
  legend->SetBackground(0.12, 0.12, 0.12);
  window->AddRenderer(legend);  // the texts are measured in it
  // Equal gaps between the texts as measured, not equal slots: a fit's
  // legend has long texts beside short ones, which slots would run together.
  std::vector<vtkTextActor*> texts;
  std::vector<double> widths;
  for (const auto& [text, colour] : items) {
    texts.push_back(addText(legend, text, 0.0, colour));
    double box[4];
    texts.back()->GetBoundingBox(legend, box);
    widths.push_back(box[1] - box[0]);
  }
  const double total = std::accumulate(widths.begin(), widths.end(), 0.0);
  const double gap = std::max(0.0, (kSlicesWidth - total) / static_cast<double>(texts.size()));
  double x = 0.5 * gap;
  for (std::size_t i = 0; i < texts.size(); ++i) {
    texts[i]->SetPosition(x / kSlicesWidth, 0.5);
    x += widths[i] + gap;
  }
}

void requireSurface(const FigureScene& scene) {
  if (!scene.surface || scene.surface->GetNumberOfPoints() == 0) throw Error("the figure has no surface to show");
}

}  // namespace

std::string coordinatesName(FigureCoordinates coordinates) {
  return coordinates == FigureCoordinates::Ras ? "RAS" : "LPS";
}

DistanceColours edgeDistanceColours() {
  return {kEdgeDistanceScalars, 0.0, style::kFarFromEdges, "an edge", "an image edge", "any edge"};
}

DistanceColours scanDistanceColours(double far) {
  return {kScanDistanceScalars, 0.5 * far, far, "the scan", "the scan", "the scan"};
}

namespace {

// The figures drawn into a window, which is sized for them (its renderers
// are the caller's to have removed).
void drawSlices(const FigureScene& scene, vtkRenderWindow* window) {
  requireSurface(scene);
  const MatrixX3 points = pointsOf(scene.surface);
  const Vector3 low = points.colwise().minCoeff().transpose(), high = points.colwise().maxCoeff().transpose();
  const Vector3 centre = 0.5 * (low + high);
  const ImageSlices* image = scene.image;
  // The slices are cut through the middle of the surface's box: another
  // image's surface, or one in other coordinates, has no slice there.
  if (image && !image->geometry().covers(centre)) {
    const std::string what =
        "the surface lies outside the image" + (scene.imageName.empty() ? "" : " " + scene.imageName) +
        " (the middle of its box is outside): nothing to show on its slices; is it another image's surface?";
    if (scene.surfaceName.empty()) throw Error(what);
    throw Error(scene.surfaceName, what);
  }
  const double diagonal = (high - low).norm();
  // The grey window of the structure's neighbourhood, shared by all slices.
  ImageSlices::GreyWindow grey;
  if (image) grey = image->windowAround(points, 10.0);

  window->SetSize(kSlicesWidth, kSlicesHeight);
  window->SetDPI(72);  // the nominal size's, at which the legend is measured (scaleFigure may have left another)
  for (int row = 0; row < 3; ++row) {
    const auto orientation = static_cast<SliceOrientation>(row);
    // The surface's extent along the slice normal and across the view.
    SlicePlane axes = image ? image->plane(orientation, 0) : anatomicalPlane(orientation, centre, 0.015 * diagonal);
    const Eigen::VectorXd along = points * axes.normal;
    const Eigen::VectorXd across = points * axes.right, upward = points * axes.up;
    // Room around the surface, 30 % of its size; around a structure in an
    // image, 3 mm of its neighbourhood too (not around a scan, which may be
    // a fraction of a mm across).
    const double halfSize =
        0.5 * 1.3 * std::max(across.maxCoeff() - across.minCoeff(), upward.maxCoeff() - upward.minCoeff()) +
        (image ? 3.0 : 0.0);
    for (int column = 0; column < kColumns; ++column) {
      SliceView view(orientation);
      view.setImage(image);
      if (image) view.setGreyWindow(grey.window, grey.level);
      view.setCoordinates(scene.coordinates);
      view.setTitleVisible(false);  // in the caption strip, clear of the edge letters
      view.setSurface(scene.surface);
      if (scene.distances) view.colourByDistance(*scene.distances);  // else by element type
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
      if (scene.outliers.rows() > 0) view.setOutliers(scene.outliers);
      view.frame(centre, halfSize);
      // Row 0 at the top of the window; the caption strip above each image.
      const int top = kSlicesHeight - row * (kCell + kCaption), x0 = column * kCell, x1 = x0 + kCell;
      view.renderer()->SetViewport(double(x0) / kSlicesWidth, double(top - kCaption - kCell) / kSlicesHeight,
                                   double(x1) / kSlicesWidth, double(top - kCaption) / kSlicesHeight);
      window->AddRenderer(view.renderer());
      auto caption = strip(x0, top - kCaption, x1, top, kSlicesWidth, kSlicesHeight);
      addText(caption, view.caption(), 0.02, {1, 1, 1});
      window->AddRenderer(caption);
    }
  }
  addLegend(scene, window);
}

// An orientation cube in the bottom-left corner, turned as the camera sees
// the surface; its faces name the anatomical directions.
void addOrientationMarker(vtkRenderer* main, vtkRenderWindow* window) {
  vtkNew<vtkAnnotatedCubeActor> cube;
  // LPS: +x to the patient's left, +y posterior, +z superior.
  cube->SetXPlusFaceText("L");
  cube->SetXMinusFaceText("R");
  cube->SetYPlusFaceText("P");
  cube->SetYMinusFaceText("A");
  cube->SetZPlusFaceText("S");
  cube->SetZMinusFaceText("I");
  cube->SetFaceTextScale(0.65);
  cube->GetCubeProperty()->SetColor(0.75, 0.75, 0.75);
  cube->GetTextEdgesProperty()->SetColor(0.3, 0.3, 0.3);
  for (vtkProperty* face : {cube->GetXPlusFaceProperty(), cube->GetXMinusFaceProperty(), cube->GetYPlusFaceProperty(),
                            cube->GetYMinusFaceProperty(), cube->GetZPlusFaceProperty(), cube->GetZMinusFaceProperty()})
    face->SetColor(0.1, 0.1, 0.5);
  vtkNew<vtkRenderer> marker;
  marker->SetViewport(0.0, 0.0, 0.16, 0.16);
  marker->SetLayer(1);  // drawn over the scene, which it does not erase
  marker->AddActor(cube);
  vtkCamera* camera = main->GetActiveCamera();
  Vector3 position, focal, up;
  camera->GetPosition(position.data());
  camera->GetFocalPoint(focal.data());
  camera->GetViewUp(up.data());
  const Vector3 direction = (position - focal).normalized();
  vtkCamera* markerCamera = marker->GetActiveCamera();
  markerCamera->SetFocalPoint(0, 0, 0);
  markerCamera->SetPosition((5.0 * direction).eval().data());
  markerCamera->SetViewUp(up.data());
  marker->ResetCamera();
  window->SetNumberOfLayers(2);
  window->AddRenderer(marker);
}

void drawSurface(const FigureScene& scene, vtkRenderWindow* window) {
  requireSurface(scene);
  window->SetSize(800, 800);
  SurfaceView view;
  view.setSurface(scene.surface);
  if (scene.distances) view.colourByDistance(*scene.distances);  // else by element type
  if (scene.controlMesh) view.setControlMesh(scene.controlMesh);
  view.setLandmarks(scene.landmarks);
  if (scene.dataPoints.rows() > 0) view.setDataPoints(scene.dataPoints);
  if (scene.outliers.rows() > 0) view.setOutliers(scene.outliers);
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
  if (scene.distances) {
    // The colour bar holds the right sixth of the view (SceneStyle.cpp):
    // the surface is framed in the rest.
    vtkCamera* camera = view.renderer()->GetActiveCamera();
    camera->Zoom(0.84);
    camera->SetWindowCenter(0.16, 0.0);
  }
  window->AddRenderer(view.renderer());
  addOrientationMarker(view.renderer(), window);
  if (scene.landmarks.rows() > 0) {
    vtkNew<vtkTextActor> legend;
    style::cornerText(legend, 0.98, 0.02, style::Corner::BottomRight);
    legend->GetTextProperty()->SetColor(landmarkColour().data());
    legend->SetInput("red dots: landmarks");
    view.renderer()->AddActor2D(legend);
  }
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
  auto window = style::offScreenWindow(kSlicesWidth, kSlicesHeight);
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

std::string figureExtension(FigureFormat format) {
  switch (format) {
    case FigureFormat::Pdf:
      return "pdf";
    case FigureFormat::Svg:
      return "svg";
    case FigureFormat::Png:
      break;
  }
  return "png";
}

namespace {

// A chart's pens (its curves' and its axes' and grid's), `scale` times as
// wide: a chart's text follows the window's DPI, its pens do not.
void scaleChart(vtkChartXY* chart, double scale) {
  for (vtkIdType p = 0; p < chart->GetNumberOfPlots(); ++p) {
    vtkPen* pen = chart->GetPlot(p)->GetPen();
    pen->SetWidth(static_cast<float>(pen->GetWidth() * scale));
  }
  for (int a = 0; a < 4; ++a)
    for (vtkPen* pen : {chart->GetAxis(a)->GetPen(), chart->GetAxis(a)->GetGridPen()})
      pen->SetWidth(static_cast<float>(pen->GetWidth() * scale));
}

// The window, and with it its text (through the window's DPI, which text
// sizes in points are drawn at), its lines, its dots and its charts' pens,
// `scale` times as large. Viewports and cameras are relative to the window
// and stay as they are.
void scaleFigure(vtkRenderWindow* window, double scale) {
  const int* size = window->GetSize();
  window->SetSize(static_cast<int>(std::lround(size[0] * scale)), static_cast<int>(std::lround(size[1] * scale)));
  window->SetDPI(static_cast<int>(std::lround(72 * scale)));
  if (scale == 1.0) return;
  vtkRendererCollection* renderers = window->GetRenderers();
  renderers->InitTraversal();
  while (vtkRenderer* renderer = renderers->GetNextItem()) {
    vtkNew<vtkPropCollection> actors;
    vtkPropCollection* props = renderer->GetViewProps();
    props->InitTraversal();
    while (vtkProp* prop = props->GetNextProp()) {
      prop->GetActors(actors);  // an assembly's parts too
      if (auto* context = vtkContextActor::SafeDownCast(prop))
        for (unsigned int i = 0; i < context->GetScene()->GetNumberOfItems(); ++i)
          if (auto* chart = vtkChartXY::SafeDownCast(context->GetScene()->GetItem(i))) scaleChart(chart, scale);
    }
    actors->InitTraversal();
    while (vtkProp* prop = actors->GetNextProp()) {
      if (auto* actor = vtkActor::SafeDownCast(prop)) {
        vtkProperty* property = actor->GetProperty();
        property->SetLineWidth(static_cast<float>(property->GetLineWidth() * scale));
        property->SetPointSize(static_cast<float>(property->GetPointSize() * scale));
      }
    }
  }
}

void writePngAt(vtkRenderWindow* window, const std::string& path, double dpi) {
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
               static_cast<const unsigned char*>(image->GetScalarPointer()), dpi);
  output.commit();
}

constexpr const char* kPdftocairoMissing =
    "PDF and SVG figures are made with pdftocairo, which is not on PATH (Debian package poppler-utils); PNG "
    "figures need nothing more";

// Runs pdftocairo with `arguments`; its messages go to `log`, which the
// error quotes when it fails.
void runPdftocairo(const std::vector<std::string>& arguments, const std::string& log, const std::string& target) {
  std::vector<char*> argv;
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  // Signals this process blocks (AtomicOutput.h's interrupt) are not blocked in pdftocairo.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, argv[0], &actions, &attributes, argv.data(), environ);
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned == ENOENT) throw writeFailure(target, kPdftocairoMissing);
  if (spawned != 0)
    throw writeFailure(target, std::string("pdftocairo could not be started: ") + std::strerror(spawned));
  int status = 0;
  pid_t waited = 0;
  while ((waited = waitpid(pid, &status, 0)) < 0 && errno == EINTR) {
  }
  if (waited < 0) throw writeFailure(target, std::string("pdftocairo was lost: ") + std::strerror(errno));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::ifstream in(log);
    const std::string messages((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    throw writeFailure(target, "pdftocairo failed: " + withoutTemporaryPrefix(messages.substr(0, 400)));
  }
}

// PDF or SVG: GL2PS draws the window as a PDF (text as outlines, the 3D
// scene as a raster of the window) whose page is the window in points;
// pdftocairo rewrites it at the figure's nominal size, as PDF or SVG.
// Debian's GL2PS cannot put a raster into SVG itself, and poppler reports
// undefined graphics states (ExtGState) in its PDFs, which cairo's rewrite
// does not have. The intermediate and pdftocairo's messages are outputs that
// are never committed: removed when done, and swept after a killed run.
void writeVectorFigure(vtkRenderWindow* window, const std::string& path, FigureFormat format, double dpi) {
  AtomicOutput output(path);
  // Beside the file being written (an output set's folder until it
  // commits), named after the figure.
  const std::filesystem::path written(path);
  const std::filesystem::path name(withoutTemporaryPrefix(written.filename().string()));
  const std::string stem = (written.parent_path() / name.stem()).string();
  AtomicOutput drawn(stem + ".gl2ps.pdf"), log(stem + ".pdftocairo.log");
  const std::string& intermediate = drawn.temporaryPath();
  window->Render();
  vtkNew<vtkGL2PSExporter> exporter;
  exporter->SetRenderWindow(window);
  // GL2PS adds the extension itself.
  exporter->SetFilePrefix(intermediate.substr(0, intermediate.size() - 4).c_str());
  exporter->SetFileFormatToPDF();
  exporter->Write3DPropsAsRasterImageOn();
  exporter->SetSortToOff();  // in drawing order: the plot's legend box over its grid
  exporter->TextAsPathOn();
  exporter->SetTitle("DynSub figure");
  exporter->Write();
  std::error_code error;
  if (std::filesystem::file_size(intermediate, error) == 0 || error)
    throw writeFailure(path, "GL2PS wrote no PDF of the figure");
  // The nominal size in points. pdftocairo takes the paper upright and
  // turns it for a landscape page, so the shorter side goes first; -expand
  // lets a page smaller than the paper (below 72 dpi) fill it.
  const int* size = window->GetSize();
  const long width = std::lround(size[0] * 72.0 / dpi), height = std::lround(size[1] * 72.0 / dpi);
  runPdftocairo({"pdftocairo", format == FigureFormat::Svg ? "-svg" : "-pdf", "-expand", "-paperw",
                 std::to_string(std::min(width, height)), "-paperh", std::to_string(std::max(width, height)),
                 intermediate, output.temporaryPath()},
                log.temporaryPath(), path);
  output.commit();
}

// Draws the window's figure as `format` at `dpi` (FigureFiles): the window,
// its text, lines and dots grow by dpi / 100 first, so the figure must be
// freshly drawn at the default resolution.
void writeFigure(vtkRenderWindow* window, const std::string& path, FigureFormat format, double dpi) {
  if (!(dpi >= kMinFigureDpi && dpi <= kMaxFigureDpi))
    throw writeFailure(path, "internal: a figure resolution outside " + std::to_string(int(kMinFigureDpi)) + "-" +
                                 std::to_string(int(kMaxFigureDpi)) + " dpi");
  scaleFigure(window, dpi / kDefaultFigureDpi);
  if (format == FigureFormat::Png) {
    writePngAt(window, path, dpi);
  } else {
    writeVectorFigure(window, path, format, dpi);
  }
}

}  // namespace

void requireFigureFormat(FigureFormat format) {
  if (format == FigureFormat::Png) return;
  const char* path = std::getenv("PATH");
  std::string directories = path ? path : "";
  std::size_t from = 0;
  while (from <= directories.size()) {
    const std::size_t to = std::min(directories.find(':', from), directories.size());
    const std::string directory = directories.substr(from, to - from);
    if (!directory.empty() && access((directory + "/pdftocairo").c_str(), X_OK) == 0) return;
    from = to + 1;
  }
  throw Error(kPdftocairoMissing);
}

void writePng(vtkRenderWindow* window, const std::string& path) { writePngAt(window, path, kDefaultFigureDpi); }

void writeFigures(const FigureInputs& inputs, const FigureFiles& files) {
  const vtkSmartPointer<vtkPolyData> surface =
      inputs.surface ? toPolyData(*inputs.surface) : readSurfacePolyData(inputs.surfaceFile);
  if (inputs.edgeDistances.size() > 0) {
    if (inputs.edgeDistances.size() != surface->GetNumberOfPoints())
      throw Error("internal: the edge distances are not one per point of the figure's surface");
    addPointData(surface, kEdgeDistanceScalars, inputs.edgeDistances);
  }
  if (inputs.scanDistances.size() > 0) {
    if (inputs.scanDistances.size() != surface->GetNumberOfPoints())
      throw Error("internal: the scan distances are not one per point of the figure's surface");
    if (!(inputs.scanDistanceFar > 0.0)) throw Error("internal: the scan distances' far distance is not positive");
    addPointData(surface, kScanDistanceScalars, inputs.scanDistances);
    addFarDistance(surface, kScanDistanceScalars, inputs.scanDistanceFar);
  }
  // The surface, given or read from its file, says what colours it.
  FigureScene scene;
  scene.surface = surface;
  if (surface->GetPointData()->GetArray(kEdgeDistanceScalars)) scene.distances = edgeDistanceColours();
  vtkDataArray* far = surface->GetFieldData()->GetArray(farName(kScanDistanceScalars).c_str());
  if (far && surface->GetPointData()->GetArray(kScanDistanceScalars)) {
    if (far->GetNumberOfTuples() != 1 || far->GetNumberOfComponents() != 1 || !(far->GetTuple1(0) > 0.0) ||
        !std::isfinite(far->GetTuple1(0)))
      throw Error(inputs.surfaceFile,
                  "its field array " + farName(kScanDistanceScalars) + " is not one positive number of mm");
    scene.distances = scanDistanceColours(far->GetTuple1(0));
  }
  scene.surfaceName = inputs.surfaceFile;
  scene.imageName = inputs.imageFile;
  scene.landmarks = inputs.landmarks;
  scene.dataPoints = inputs.dataPoints;
  scene.outliers = inputs.outliers;
  scene.coordinates = inputs.coordinates;
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
  // One window for all three: creating a window (choosing its GLX
  // framebuffer configuration, starting its context) costs a sizeable share
  // of the figures' time. Each figure's renderers leave it before the next's
  // come.
  const vtkSmartPointer<vtkRenderWindow> window = style::offScreenWindow(kSlicesWidth, kSlicesHeight);
  auto draw = [&](const std::string& path, const auto& figure) {
    if (path.empty()) return;
    while (vtkRenderer* previous = window->GetRenderers()->GetFirstRenderer()) window->RemoveRenderer(previous);
    figure();
    writeFigure(window, path, files.format, files.dpi);
  };
  draw(files.slices, [&] { drawSlices(scene, window); });
  draw(files.surface3d, [&] { drawSurface(scene, window); });
  draw(files.convergence, [&] { drawConvergence(*inputs.history, window); });
}

}  // namespace dynsub
