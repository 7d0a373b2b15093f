// Rendering tests (they need an X display: ctest runs under xvfb-run).
//  - Placement: pixels of a slice view of an oblique, anisotropic phantom are
//    where the phantom's analytic sphere says, with the contour and landmarks
//    on top: the image, the surface and the points share one LPS frame.
//  - Baselines: the figures compared with Testing/Data/Baseline/<TestName>.png
//    through vtkTesting, which must report PASSED. Threshold 0.15, VTK's own
//    default: a sum over pixels of per-channel excess over 105 after VTK's
//    +-2 pixel shift and 3 x 3 averaging, so it tolerates no visible change.
//    A missing or changed baseline leaves the new image (and a .diff.png) in
//    build/Testing/Temporary for review.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <array>
#include <string>
#include <vector>

#include <vtkActor2DCollection.h>
#include <vtkCellData.h>
#include <vtkChartXY.h>
#include <vtkCoordinate.h>
#include <vtkCutter.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPlane.h>
#include <vtkPNGReader.h>
#include <vtkPlot.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkTextActor.h>
#include <vtkSphereSource.h>
#include <vtkTesting.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>
#include <vtkXMLPolyDataWriter.h>

#include "BallPhantom.h"
#include "dynsub/ConvergenceHistory.h"
#include "dynsub/ConvergencePlot.h"
#include "dynsub/Error.h"
#include "dynsub/Figures.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Landmarks.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/MeshIO.h"
#include "dynsub/Sculpting.h"
#include "dynsub/SliceView.h"
#include "dynsub/SolidView.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/SurfaceWriter.h"
#include "dynsub/SurfaceView.h"
#include "dynsub/Tessellation.h"
#include "dynsub/Voxelize.h"

namespace dynsub {
namespace {

const std::string kSource = DYNSUB_SOURCE_DIR;
const std::string kMri = "/usr/share/mricron/templates/ch2.nii.gz";

class Rendering : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!displayAvailable(&why)) FAIL() << "rendering tests need an X display: " << why;
  }
};

// Where the tests leave their images for review (made if missing).
std::string temporaryDirectory() {
  const std::string directory = std::string(DYNSUB_BINARY_DIR) + "/Testing/Temporary";
  std::filesystem::create_directories(directory);
  return directory;
}

void expectMatchesBaseline(vtkRenderWindow* window) {
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const std::string baseline = kSource + "/Testing/Data/Baseline/" + name + ".png";
  const std::string temporary = temporaryDirectory();
  window->Render();
  vtkNew<vtkTesting> testing;
  testing->AddArgument("-V");
  testing->AddArgument(baseline.c_str());
  testing->AddArgument("-T");
  testing->AddArgument(temporary.c_str());
  testing->SetRenderWindow(window);
  const int result = testing->RegressionTest(0.15);
  EXPECT_EQ(result, vtkTesting::PASSED) << "against " << baseline << " (new image in " << temporary << ")";
}

TriangleSurface limitTessellationOf(const std::string& meshFile) {
  const ControlMesh mesh = readControlMesh(meshFile);
  return tessellate(LimitSurface(mesh), mesh.points(), 8);
}

vtkSmartPointer<vtkPolyData> limitSurfaceOf(const std::string& meshFile) {
  return toPolyData(limitTessellationOf(meshFile));
}

// --- placement ------------------------------------------------------------

std::array<int, 3> pixel(vtkImageData* image, const Eigen::Vector2d& at) {
  const int x = static_cast<int>(std::lround(at.x())), y = static_cast<int>(std::lround(at.y()));
  const auto* rgb = static_cast<unsigned char*>(image->GetScalarPointer(x, y, 0));
  return {rgb[0], rgb[1], rgb[2]};
}

// The pixels of a PNG file that `match`, from row `fromRow` (counted from
// the bottom) up and left of `widthFraction` of its width.
int countPixels(const std::string& file, const std::function<bool(const std::array<int, 3>&)>& match, int fromRow = 0,
                double widthFraction = 1.0) {
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int size[3];
  image->GetDimensions(size);
  int count = 0;
  for (int y = fromRow; y < size[1]; ++y)
    for (int x = 0; x < widthFraction * size[0]; ++x) count += match(pixel(image, Eigen::Vector2d(x, y)));
  return count;
}

// The phantom's analytic ball as a finely tessellated sphere, for the slice
// views to cut.
vtkSmartPointer<vtkPolyData> phantomBall(const BallPhantom& phantom) {
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(phantom.centre.data());
  sphere->SetRadius(phantom.radius);
  sphere->SetThetaResolution(128);
  sphere->SetPhiResolution(128);
  sphere->Update();
  auto surface = vtkSmartPointer<vtkPolyData>::New();
  surface->ShallowCopy(sphere->GetOutput());
  return surface;
}

// `view` alone in a 400 x 400 offscreen window, and its pixels. The window
// is kept: the view's display positions are the window's.
struct Rendered {
  vtkSmartPointer<vtkRenderWindow> window;
  vtkSmartPointer<vtkImageData> image;
};

Rendered rendered(const SliceView& view) {
  auto window = vtkSmartPointer<vtkRenderWindow>::New();
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(400, 400);
  window->AddRenderer(view.renderer());
  window->Render();
  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(window);
  capture->ReadFrontBufferOff();
  capture->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(capture->GetOutput());
  return {window, image};
}

TEST_F(Rendering, SliceViewPutsImageContourAndLandmarksInOneFrame) {
  const BallPhantom phantom = makeBallPhantom();
  const ImageSlices slices(phantom.image);
  const vtkSmartPointer<vtkPolyData> surface = phantomBall(phantom);
  vtkNew<vtkUnsignedCharArray> type;  // all normal elements: yellow
  type->SetName("ElementType");
  type->SetNumberOfTuples(surface->GetNumberOfCells());
  type->FillValue(0);
  surface->GetCellData()->AddArray(type);

  for (SliceOrientation orientation : {SliceOrientation::Axial, SliceOrientation::Coronal, SliceOrientation::Sagittal}) {
    SCOPED_TRACE(orientationName(orientation));
    SliceView view(orientation);
    view.setImage(&slices);
    view.setSurface(surface);
    // A slice 3 voxels off the centre, so the circle is smaller than the ball.
    view.showSlice(slices.sliceThrough(orientation, phantom.centre) + 3);
    const SlicePlane& plane = view.plane();
    const Vector3 circleCentre = phantom.centre - plane.distance(phantom.centre) * plane.normal;
    const double circleRadius = std::sqrt(std::pow(phantom.radius, 2) - std::pow(plane.distance(phantom.centre), 2));
    const Vector3 onSlice = circleCentre + 0.5 * circleRadius * plane.right;
    const Vector3 offSlice = circleCentre - 0.5 * circleRadius * plane.right + 2.0 * plane.thickness * plane.normal;
    MatrixX3 landmarks(2, 3);
    landmarks << onSlice.transpose(), offSlice.transpose();
    view.setLandmarks(landmarks);
    view.frame(circleCentre, 20.0);

    const Rendered shown = rendered(view);
    vtkImageData* image = shown.image;

    // Inside and outside the circle by 2.5 mm (voxels are at most 1.5 mm; the
    // view shows the nearest voxel) along 12 directions, away from the landmarks.
    for (int a = 0; a < 12; ++a) {
      const double angle = (a + 0.5) * M_PI / 6.0;
      const Vector3 direction = std::cos(angle) * plane.right + std::sin(angle) * plane.up;
      const auto inside = pixel(image, view.displayPosition(circleCentre + (circleRadius - 2.5) * direction));
      const auto outside = pixel(image, view.displayPosition(circleCentre + (circleRadius + 2.5) * direction));
      EXPECT_GT(inside[1], 200) << "angle " << angle << ": the ball's voxels are not inside the circle";
      EXPECT_LT(outside[1], 50) << "angle " << angle << ": background voxels inside the circle";
      // The contour (2 px wide, yellow) on the circle: red high, blue low
      // somewhere within a pixel of the point.
      const Eigen::Vector2d on = view.displayPosition(circleCentre + circleRadius * direction);
      bool yellow = false;
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy) {
          const auto c = pixel(image, on + Eigen::Vector2d(dx, dy));
          yellow = yellow || (c[0] > 200 && c[1] > 150 && c[2] < 100);
        }
      EXPECT_TRUE(yellow) << "angle " << angle << ": no contour on the circle";
    }
    const auto landmark = pixel(image, view.displayPosition(onSlice));
    EXPECT_GT(landmark[0], 180);
    EXPECT_LT(landmark[1], 90) << "the landmark on the slice is not drawn red where it is";
    const auto hidden = pixel(image, view.displayPosition(offSlice - plane.distance(offSlice) * plane.normal));
    EXPECT_GT(hidden[1], 200) << "a landmark two slices away is drawn";
    EXPECT_EQ(view.landmarksOnSlice(), std::vector<int>{0});
    // Display -> slice point -> display is the identity.
    const Vector3 back = view.pointAt(200, 210);
    EXPECT_NEAR(plane.distance(back), 0.0, 1e-9);
    EXPECT_NEAR((view.displayPosition(back) - Eigen::Vector2d(200, 210)).norm(), 0.0, 1e-6);
  }
}

// A segmentation's contour coloured by its distance to the image's edges:
// on a ball whose points say 0 mm (held by an edge) on the view's left half,
// 5 mm (beyond kFarFromEdges) on its upper right quarter and -1 (unknown) on
// its lower right one, the contour is green, magenta and grey where they are.
TEST_F(Rendering, SliceViewColoursTheContourByEdgeDistance) {
  const BallPhantom phantom = makeBallPhantom();
  const ImageSlices slices(phantom.image);
  const vtkSmartPointer<vtkPolyData> surface = phantomBall(phantom);

  SliceView view(SliceOrientation::Coronal);
  view.setImage(&slices);
  view.setSurface(surface);
  view.colourByDistance(edgeDistanceColours());
  view.showSlice(slices.sliceThrough(SliceOrientation::Coronal, phantom.centre));
  const SlicePlane& plane = view.plane();
  vtkNew<vtkDoubleArray> distances;
  distances->SetName(kEdgeDistanceScalars);
  distances->SetNumberOfTuples(surface->GetNumberOfPoints());
  for (vtkIdType p = 0; p < surface->GetNumberOfPoints(); ++p) {
    double x[3];
    surface->GetPoint(p, x);
    const Vector3 d = Vector3(x[0], x[1], x[2]) - phantom.centre;
    distances->SetValue(p, d.dot(plane.right) < 0 ? 0.0 : d.dot(plane.up) > 0 ? 5.0 : -1.0);
  }
  surface->GetPointData()->AddArray(distances);
  const Vector3 circleCentre = phantom.centre - plane.distance(phantom.centre) * plane.normal;
  const double circleRadius = std::sqrt(std::pow(phantom.radius, 2) - std::pow(plane.distance(phantom.centre), 2));
  view.frame(circleCentre, 20.0);

  const Rendered shown = rendered(view);
  vtkImageData* image = shown.image;

  // The colours within a pixel of the circle, 15 degrees and more from the
  // quarters' borders (where the colours blend over a triangle).
  auto near = [&](const Vector3& direction, auto isColour) {
    const Eigen::Vector2d on = view.displayPosition(circleCentre + circleRadius * direction);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        if (isColour(pixel(image, on + Eigen::Vector2d(dx, dy)))) return true;
    return false;
  };
  const auto green = [](const std::array<int, 3>& c) { return c[1] > 150 && c[0] < 100 && c[2] < 120; };
  const auto magenta = [](const std::array<int, 3>& c) { return c[0] > 180 && c[2] > 180 && c[1] < 100; };
  const auto grey = [](const std::array<int, 3>& c) {
    return std::abs(c[0] - c[1]) < 12 && std::abs(c[1] - c[2]) < 12 && c[0] > 110 && c[0] < 170;
  };
  for (int a = 0; a < 12; ++a) {
    const double angle = (a + 0.5) * M_PI / 6.0;  // from the view's right, counter-clockwise
    if (std::abs(std::remainder(angle, M_PI / 2)) < M_PI / 12) continue;  // a quarter's border
    const Vector3 direction = std::cos(angle) * plane.right + std::sin(angle) * plane.up;
    const bool left = std::cos(angle) < 0, up = std::sin(angle) > 0;
    if (left) {
      EXPECT_TRUE(near(direction, green)) << "angle " << angle << ": a point held by an edge is not green";
    } else if (up) {
      EXPECT_TRUE(near(direction, magenta)) << "angle " << angle << ": a point far from edges is not magenta";
    } else {
      EXPECT_TRUE(near(direction, grey)) << "angle " << angle << ": a point of unknown distance is not grey";
    }
    EXPECT_FALSE(near(direction, [](const std::array<int, 3>& c) { return c[0] > 200 && c[1] > 150 && c[2] < 100; }))
        << "angle " << angle << ": the contour is drawn by element type (yellow)";
  }
}

// The contour a slice view draws lies on the boundary of the labelmap that
// segment writes, on the same slice of the real MRI's grid: the figures show
// the surface on the right slices in the right place. (No rendering needed:
// the view's cut plane is what it draws.)
TEST(SliceContours, LieOnTheLabelmapBoundaryOfTheirSlice) {
  const Volume mri = readVolume(kMri);
  const TriangleSurface triangles = limitTessellationOf(kSource + "/Testing/Data/caudate_left_control_mesh.obj");
  const Mask labelmap = voxelizeSurface(triangles.points, triangles.triangles, mri.geometry);
  const vtkSmartPointer<vtkPolyData> surface = toPolyData(triangles);
  const ImageSlices slices(mri);
  const ImageGeometry& g = mri.geometry;
  const Vector3 centre = triangles.points.colwise().mean().transpose();
  int points = 0, onBoundary = 0;
  for (SliceOrientation o : {SliceOrientation::Axial, SliceOrientation::Coronal, SliceOrientation::Sagittal}) {
    const int axis = slices.axis(o);
    for (int offset = -6; offset <= 6; offset += 3) {
      SliceView view(o);
      view.setImage(&slices);
      view.showSlice(slices.sliceThrough(o, centre) + offset);
      const SlicePlane& plane = view.plane();
      vtkNew<vtkPlane> cut;
      cut->SetOrigin(plane.origin.x(), plane.origin.y(), plane.origin.z());
      cut->SetNormal(plane.normal.x(), plane.normal.y(), plane.normal.z());
      vtkNew<vtkCutter> cutter;
      cutter->SetCutFunction(cut);
      cutter->SetInputData(surface);
      cutter->Update();
      vtkPoints* contour = cutter->GetOutput()->GetPoints();
      ASSERT_TRUE(contour && contour->GetNumberOfPoints() > 10) << orientationName(o) << " " << offset;
      for (vtkIdType i = 0; i < contour->GetNumberOfPoints(); ++i) {
        double p[3];
        contour->GetPoint(i, p);
        const Vector3 index = g.toIndex(Vector3(p[0], p[1], p[2]));
        ASSERT_NEAR(index[axis], view.sliceIndex(), 1e-6) << "the contour is not on the slice shown";
        // Inside and outside voxels both within one voxel in the slice.
        bool inside = false, outside = false;
        const int ci = static_cast<int>(std::lround(index[0])), cj = static_cast<int>(std::lround(index[1])),
                  ck = static_cast<int>(std::lround(index[2]));
        for (int di = -1; di <= 1; ++di)
          for (int dj = -1; dj <= 1; ++dj)
            for (int dk = -1; dk <= 1; ++dk) {
              const int d[3] = {di, dj, dk};
              if (d[axis] != 0) continue;
              const int i2 = ci + di, j2 = cj + dj, k2 = ck + dk;
              if (!g.contains(i2, j2, k2)) continue;
              (labelmap.voxels[g.offset(i2, j2, k2)] ? inside : outside) = true;
            }
        ++points;
        onBoundary += inside && outside;
      }
    }
  }
  // Where the surface grazes a slice, its contour can pass between voxel
  // centres without a voxel of each kind next to it: allow 2 % of points.
  EXPECT_GE(onBoundary, 0.98 * points) << onBoundary << " of " << points << " contour points on the boundary";
  std::cout << onBoundary << " of " << points << " contour points lie on the labelmap's boundary\n";
}

// --- baselines --------------------------------------------------------------

// The left caudate of Colin27, its surface and its landmarks: the slices
// figure's scene (it points into this object, which therefore stays put).
struct CaudateScene {
  CaudateScene() {
    scene.image = &mri;
    scene.surface = surface;
    scene.landmarks = landmarkPositions(readLandmarks(kSource + "/Data/Landmarks/caudate_left.mrk.json"));
  }
  CaudateScene(const CaudateScene&) = delete;
  CaudateScene& operator=(const CaudateScene&) = delete;

  const ImageSlices mri{readVolume(kMri)};
  const vtkSmartPointer<vtkPolyData> surface =
      limitSurfaceOf(kSource + "/Testing/Data/caudate_left_control_mesh.obj");
  FigureScene scene;
};

TEST_F(Rendering, TestCaudateSlices) {
  const CaudateScene caudate;
  expectMatchesBaseline(slicesFigure(caudate.scene));
}

// Every text of a figure, as display-pixel boxes (x0, x1, y0, y1).
std::vector<std::array<double, 4>> textBoxes(vtkRenderWindow* window, std::vector<std::string>* texts) {
  window->Render();
  std::vector<std::array<double, 4>> boxes;
  vtkRendererCollection* renderers = window->GetRenderers();
  renderers->InitTraversal();
  while (vtkRenderer* renderer = renderers->GetNextItem()) {
    vtkActor2DCollection* actors = renderer->GetActors2D();
    actors->InitTraversal();
    while (vtkActor2D* actor = actors->GetNextActor2D()) {
      auto* text = vtkTextActor::SafeDownCast(actor);
      if (!text || !text->GetVisibility() || !text->GetInput() || std::string(text->GetInput()).empty()) continue;
      std::array<double, 4> box{};
      // The box around the text's anchor, moved to the anchor's place in
      // the renderer's viewport, then to the viewport's place in the window.
      text->GetBoundingBox(renderer, box.data());
      const int* anchor = text->GetPositionCoordinate()->GetComputedViewportValue(renderer);
      const double* viewport = renderer->GetViewport();
      const int* size = window->GetSize();
      for (int c = 0; c < 2; ++c) box[c] += anchor[0] + viewport[0] * size[0];
      for (int c = 2; c < 4; ++c) box[c] += anchor[1] + viewport[1] * size[1];
      boxes.push_back(box);
      texts->push_back(text->GetInput());
    }
  }
  return boxes;
}

// No two texts of the slices figure overlap or touch: captions, edge letters and the
// legend each have room of their own, whatever the slice numbers. `legend`
// entries are expected.
void expectTextsApart(vtkRenderWindow* window, std::size_t legend) {
  std::vector<std::string> texts;
  const auto boxes = textBoxes(window, &texts);
  // 15 captions, 60 edge letters and the legend's entries.
  EXPECT_EQ(boxes.size(), 15u + 60u + legend);
  for (std::size_t a = 0; a < boxes.size(); ++a)
    for (std::size_t b = a + 1; b < boxes.size(); ++b) {
      // At least kGap pixels apart: texts that touch read as one.
      constexpr double kGap = 2.0;
      const bool apart = boxes[a][1] + kGap <= boxes[b][0] || boxes[b][1] + kGap <= boxes[a][0] ||
                         boxes[a][3] + kGap <= boxes[b][2] || boxes[b][3] + kGap <= boxes[a][2];
      EXPECT_TRUE(apart) << "'" << texts[a] << "' overlaps '" << texts[b] << "'";
    }
}

TEST_F(Rendering, SlicesFigureTextsDoNotOverlap) {
  CaudateScene caudate;
  caudate.scene.distances = edgeDistanceColours();
  expectTextsApart(slicesFigure(caudate.scene), 4);
}

// The longest legend: a fit's colours by the distance to the scan (two long
// texts), with landmarks, range data and outliers set aside beside them.
TEST_F(Rendering, TheFullestLegendDoesNotOverlap) {
  CaudateScene caudate;
  caudate.scene.distances = scanDistanceColours(0.115);
  caudate.scene.dataPoints = caudate.scene.landmarks;
  caudate.scene.outliers = caudate.scene.landmarks.topRows(3);
  expectTextsApart(slicesFigure(caudate.scene), 6);
}

// A fit's outliers are drawn as orange dots in both figures, and only when
// given: points 15-25 % of its half-size off a cube, around it.
TEST_F(Rendering, OutliersAreDrawnInTheirOwnColour) {
  const TriangleSurface surface = limitTessellationOf(kSource + "/Data/Meshes/cube.obj");
  const Vector3 low = surface.points.colwise().minCoeff().transpose();
  const Vector3 high = surface.points.colwise().maxCoeff().transpose();
  const Vector3 centre = 0.5 * (low + high);
  const double reach = 0.5 * (high - low).maxCoeff();
  MatrixX3 outliers(12, 3);
  for (int i = 0; i < 12; ++i) {
    const double angle = 2.0 * M_PI * i / 12.0;
    const Vector3 towards(std::cos(angle), std::sin(angle), i % 2 ? 0.5 : -0.5);
    outliers.row(i) = (centre + (1.15 + 0.05 * (i % 3)) * reach * towards.normalized()).transpose();
  }
  const std::string directory = temporaryDirectory();
  const auto orangePixels = [&](const std::string& name, const MatrixX3& drawn) {
    FigureInputs inputs;
    inputs.surface = &surface;
    inputs.outliers = drawn;
    FigureFiles files;
    files.surface3d = directory + "/outliers_" + name + "_3d.png";
    files.slices = directory + "/outliers_" + name + "_slices.png";
    writeFigures(inputs, files);
    const auto orange = [](const std::array<int, 3>& c) {
      return c[0] > 220 && c[1] > 100 && c[1] < 170 && c[2] < 60;
    };
    // The slices' legend (the bottom 26 rows) names the outliers in orange too.
    return std::array<int, 2>{countPixels(files.surface3d, orange), countPixels(files.slices, orange, 30)};
  };
  const std::array<int, 2> with = orangePixels("with", outliers), without = orangePixels("without", MatrixX3());
  // A dot covers 15-20 pixels. In 3D the cube hides most of the 12 and the
  // camera frames the cube, so two show (39 pixels, measured); the slices
  // show those within half a slice of their planes. At least one dot each.
  EXPECT_GE(with[0], 10) << "3D figure";
  EXPECT_GE(with[1], 10) << "slices";
  EXPECT_EQ(without[0], 0);
  EXPECT_EQ(without[1], 0);
}

// A fit's figures colour its surface by the distance to its scan. A cube's
// limit surface whose points on one side lie on the scan (0 mm) and on the
// other beyond the far distance shows green and magenta in the 3D figure.
// Up to half the far distance it is green as on the scan, and shows no
// magenta. The colour bar (right of 84 % of the width, SceneStyle.cpp) holds
// both colours whatever the surface, so only the pixels left of 80 % are
// counted. The slices' legend names the scan and the far distance.
TEST_F(Rendering, FitFiguresColourTheSurfaceByScanDistance) {
  const TriangleSurface surface = limitTessellationOf(kSource + "/Data/Meshes/cube.obj");
  const Eigen::Index n = surface.points.rows();
  const double centre = surface.points.col(0).mean();
  const std::string directory = temporaryDirectory();
  struct Counts {
    int green = 0, magenta = 0;
  };
  const auto figureColours = [&](const std::string& name, const Eigen::VectorXd& distances) {
    FigureInputs inputs;
    inputs.surface = &surface;
    inputs.scanDistances = distances;
    inputs.scanDistanceFar = 0.5;
    FigureFiles files;
    files.surface3d = directory + "/scan_distance_" + name + ".png";
    writeFigures(inputs, files);
    Counts counts;
    counts.green = countPixels(
        files.surface3d, [](const std::array<int, 3>& c) { return c[1] > 150 && c[0] < 100 && c[2] < 120; }, 0, 0.8);
    counts.magenta = countPixels(
        files.surface3d, [](const std::array<int, 3>& c) { return c[0] > 180 && c[2] > 180 && c[1] < 100; }, 0, 0.8);
    return counts;
  };
  const Eigen::VectorXd halfFar = (surface.points.col(0).array() < centre).select(Eigen::VectorXd::Zero(n), 1.0);
  const Counts on = figureColours("on", Eigen::VectorXd::Zero(n));
  const Counts half = figureColours("half", halfFar);
  const Counts covered = figureColours("covered", Eigen::VectorXd::Constant(n, 0.24));
  // The camera looks from the left, front and top: the half at x > centre
  // shows a whole face and more than half of two others, the half at
  // x < centre a strip of those two: 14 % of the green pixels of the cube
  // all on the scan, 62 % magenta (measured; the bounds leave room).
  EXPECT_GT(on.green, 10000);
  EXPECT_GT(half.green, 0.07 * on.green);
  EXPECT_GT(half.magenta, 0.3 * on.green);
  // 0.24 mm lies in the table's entries below near (0.25 mm), all pure green;
  // the texture lookup may blend in the next entry, a shade off it: 1 %.
  EXPECT_GE(covered.green, 0.99 * on.green);
  EXPECT_EQ(covered.magenta, 0);

  const vtkSmartPointer<vtkPolyData> polyData = toPolyData(surface);
  FigureScene scene;
  scene.surface = polyData;
  scene.distances = scanDistanceColours(0.5);
  std::vector<std::string> texts;
  textBoxes(slicesFigure(scene), &texts);
  EXPECT_NE(std::find(texts.begin(), texts.end(), "contour within 0.25 mm of the scan"), texts.end());
  EXPECT_NE(std::find(texts.begin(), texts.end(), "contour 0.5 mm or more from the scan"), texts.end());

  // A surface file whose far distance is not one positive number is refused,
  // by name, before any figure is drawn.
  const std::string file = directory + "/bad_far.vtp";
  addPointData(polyData, kScanDistanceScalars, halfFar);
  addFarDistance(polyData, kScanDistanceScalars, -1.0);
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(polyData);
  writer->SetFileName(file.c_str());
  ASSERT_EQ(writer->Write(), 1);
  FigureInputs fromFile;
  fromFile.surfaceFile = file;
  FigureFiles files;
  files.surface3d = directory + "/bad_far_3d.png";
  std::filesystem::remove(files.surface3d);
  try {
    writeFigures(fromFile, files);
    ADD_FAILURE() << "a negative far distance was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad_far.vtp"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(files.surface3d));
}

// The captions name the coordinate system; RAS negates x and y, not z.
TEST_F(Rendering, SliceCaptionsNameTheirCoordinates) {
  const ImageSlices mri(readVolume(kMri));
  SliceView sagittal(SliceOrientation::Sagittal), axial(SliceOrientation::Axial);
  sagittal.setImage(&mri);
  axial.setImage(&mri);
  sagittal.showSlice(mri.sliceThrough(SliceOrientation::Sagittal, Vector3(12, 0, 0)));
  axial.showSlice(mri.sliceThrough(SliceOrientation::Axial, Vector3(0, 0, 12)));
  EXPECT_NE(sagittal.caption().find("LPS x = 12.0 mm"), std::string::npos) << sagittal.caption();
  EXPECT_NE(axial.caption().find("LPS z = 12.0 mm"), std::string::npos) << axial.caption();
  sagittal.setCoordinates(FigureCoordinates::Ras);
  axial.setCoordinates(FigureCoordinates::Ras);
  EXPECT_NE(sagittal.caption().find("RAS x = -12.0 mm"), std::string::npos) << sagittal.caption();
  EXPECT_NE(axial.caption().find("RAS z = 12.0 mm"), std::string::npos) << axial.caption();
}

// The 3D figure of a control mesh's limit surface with its wireframe.
void expectElementsMatchBaseline(const std::string& meshFile) {
  FigureScene scene;
  const vtkSmartPointer<vtkPolyData> surface = limitSurfaceOf(meshFile);
  const vtkSmartPointer<vtkPolyData> wireframe = controlMeshWireframe(readControlMesh(meshFile));
  scene.surface = surface;
  scene.controlMesh = wireframe;
  expectMatchesBaseline(surfaceFigure(scene));
}

TEST_F(Rendering, TestCubeElements) { expectElementsMatchBaseline(kSource + "/Data/Meshes/cube.obj"); }

TEST_F(Rendering, TestTorusElements) { expectElementsMatchBaseline(kSource + "/Data/Meshes/torus.obj"); }

// The cube with sharp edges: flat faces lit apart, its creases drawn orange-red.
TEST_F(Rendering, TestSharpCubeElements) { expectElementsMatchBaseline(kSource + "/Data/Meshes/cube_sharp.obj"); }

TEST(ControlMeshWireframe, CreasesAreColouredApart) {
  const vtkSmartPointer<vtkPolyData> plain = controlMeshWireframe(readControlMesh(kSource + "/Data/Meshes/cube.obj"));
  EXPECT_EQ(plain->GetNumberOfLines(), 192);
  EXPECT_EQ(plain->GetCellData()->GetScalars(), nullptr);  // the actor's colour, as before

  const vtkSmartPointer<vtkPolyData> sharp =
      controlMeshWireframe(readControlMesh(kSource + "/Data/Meshes/cube_sharp.obj"));
  ASSERT_EQ(sharp->GetNumberOfLines(), 12);
  vtkDataArray* colours = sharp->GetCellData()->GetScalars();
  ASSERT_NE(colours, nullptr);
  int creases = 0;
  for (vtkIdType c = 0; c < colours->GetNumberOfTuples(); ++c) creases += colours->GetComponent(c, 0) == 255;
  EXPECT_EQ(creases, 12);
}

TEST_F(Rendering, TestConvergencePlot) {
  expectMatchesBaseline(convergenceFigure(readConvergenceCsv(kSource + "/Testing/Data/caudate_left_convergence.csv")));
}

// A fit that ends in two steps and measured its error at one of them (the
// torus demo's): the error is a marker, as VTK draws no line through one point.
TEST(ConvergencePlot, ASeriesOfOnePointIsAMarker) {
  ConvergenceHistory history;
  history.fitErrorName = "max error (%)";
  history.add({0, 1, 6404.9, 1.02});
  history.add({0, 2, 6399.1});
  const vtkSmartPointer<vtkChartXY> chart = convergenceChart(history);
  ASSERT_EQ(chart->GetNumberOfPlots(), 2);
  EXPECT_TRUE(chart->GetPlot(0)->IsA("vtkPlotLine")) << "the energy, two points";
  EXPECT_FALSE(chart->GetPlot(1)->IsA("vtkPlotLine")) << "the error, one point";
  EXPECT_TRUE(chart->GetPlot(1)->IsA("vtkPlotPoints"));
}

// Sculpted Cube 3^3: the base fixed (red points), an arm of three extruded
// cells bent by the rope and kept by plasticity, a cell deleted (its faces now
// on the surface, lit from outside).
TEST_F(Rendering, TestSculptedArm) {
  const Lattice cube3 = regularLattice(2, 2, 2);
  Sculpture s(cube3);
  s.fix({0, 1, 2, 3, 4, 5, 6, 7, 8});
  int face = s.boundaryFaceNear(Vector3(1.5, 1.5, 2));
  for (int i = 0; i < 3; ++i) face = s.extrude(face);
  s.grab(Vector3(2, 2, 5));
  s.pullTo(Vector3(3.5, 2, 5));
  s.run(600);
  s.plasticity();
  s.release();
  s.run(200);
  s.deleteCell(s.cellNear(Vector3(0.5, 0.5, 1.5)));
  expectMatchesBaseline(sculptureFigure(s));
}

}  // namespace
}  // namespace dynsub
