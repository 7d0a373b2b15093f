#pragma once
// The figures `dynsub segment`, `dynsub fit` and `dynsub render` write
// (TVCG Figs 6, 10, 11):
//   slices.png       3 rows (axial, coronal, sagittal) x 5 slices through the
//                    surface: the image (windowed on the surface's
//                    neighbourhood), the surface's contour, the landmarks on
//                    each slice (or the range data near it); a caption strip
//                    above each slice naming its coordinate (LPS or RAS), and
//                    a legend strip at the bottom; 1200 x 800;
//   surface3d.png    the limit surface coloured by element type, landmarks or
//                    data, and (with an image) three slices behind the surface
//                    as a backdrop, an orientation cube; 800 x 800;
//   A surface that carries its distance to the image's edges (a
//   segmentation's) or to its scan (a fit's) is coloured by it instead, in
//   both (FigureScene::distances).
//   convergence.png  the convergence plot (ConvergencePlot.h); 900 x 500.
// Windows are fixed-size, without multisampling, and render off screen, so
// the same input gives the same pixels (rendering regression tests rely on it).
//
// Debian's VTK renders through X11 only: an X display is needed, or VTK
// aborts the process. displayAvailable says whether one can be opened;
// figureDisplay provides one on a machine without a screen.
#include <optional>
#include <string>

#include <vtkSmartPointer.h>

#include "dynsub/ConvergenceHistory.h"
#include "dynsub/FigureInputs.h"
#include "dynsub/Types.h"

class vtkPolyData;
class vtkRenderWindow;

namespace dynsub {

class ImageSlices;

// Not owned; one ImageSlices (the image's VTK copy) serves every figure.
struct FigureScene {
  const ImageSlices* image = nullptr; // optional (SlicePlanes.h)
  vtkPolyData* surface = nullptr;     // the limit surface, required (SurfacePolyData.h)
  vtkPolyData* controlMesh = nullptr; // optional wireframe (SurfaceView.h), 3D figure only
  MatrixX3 landmarks;                 // #landmarks x 3, LPS mm
  MatrixX3 dataPoints;                // range data, mm
  MatrixX3 outliers;                  // range data set aside as outliers, mm
  // The surface and its contours coloured by a distance of each point
  // (FigureInputs.h), with a colour bar in the 3D figure; none: by element
  // type.
  std::optional<DistanceColours> distances;
  FigureCoordinates coordinates = FigureCoordinates::Lps;  // the ones the slice captions print
  std::string surfaceName, imageName;  // their files, for messages (empty: none)
};

// Throws dynsub::Error when the scene has no surface, or (slices) when the
// surface lies outside the image.
vtkSmartPointer<vtkRenderWindow> slicesFigure(const FigureScene& scene);
vtkSmartPointer<vtkRenderWindow> surfaceFigure(const FigureScene& scene);
// Throws dynsub::Error for an empty history.
vtkSmartPointer<vtkRenderWindow> convergenceFigure(const ConvergenceHistory& history);

// Renders the window as it is and writes it as PNG at the default
// resolution; the file appears complete or not at all. Throws dynsub::Error
// naming the file.
void writePng(vtkRenderWindow* window, const std::string& path);

}  // namespace dynsub
