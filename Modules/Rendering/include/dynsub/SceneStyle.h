#pragma once
// The look every view shares (colours, sizes, text placement) and the
// conversions between world and display points, for the Rendering module's
// views and the Interaction module's windows.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <vtkSmartPointer.h>

#include "dynsub/FigureInputs.h"
#include "dynsub/Types.h"

class vtkActor;
class vtkCallbackCommand;
class vtkPolyData;
class vtkPolyDataMapper;
class vtkRenderWindow;
class vtkRenderWindowInteractor;
class vtkRenderer;
class vtkScalarBarActor;
class vtkTextActor;

namespace dynsub::style {

// The papers draw normal elements yellow and special ones green.
constexpr std::array<double, 3> kNormalElement{1.0, 0.85, 0.1};
constexpr std::array<double, 3> kSpecialElement{0.2, 0.8, 0.3};
constexpr std::array<unsigned char, 3> kLandmark{230, 40, 40};
constexpr std::array<unsigned char, 3> kSelectedLandmark{40, 220, 240};
constexpr double kLandmarkPixels = 9.0;
constexpr double kDataPixels = 3.0;
constexpr double kCameraDistance = 1000.0;  // mm, slice views (parallel projection)
constexpr int kFontSize = 14;

// Colours a mapper's cells by the "ElementType" cell array (SurfacePolyData.h).
void colourByElementType(vtkPolyDataMapper* mapper);
// Colours a mapper's points by a distance (DistanceColours, FigureInputs.h).
// Throws dynsub::Error unless 0 <= near < far, both finite.
void colourByDistance(vtkPolyDataMapper* mapper, const DistanceColours& colours);
constexpr double kFarFromEdges = 3.0;  // mm: three voxels of the 1 mm MRI
// The distance colours: green up to the near distance, through yellow, to
// magenta at the far distance and beyond (not red, which the landmarks are
// drawn in).
constexpr std::array<double, 3> kNearColour{0.15, 0.8, 0.25};
constexpr std::array<double, 3> kMiddleColour{1.0, 0.9, 0.15};
constexpr std::array<double, 3> kFarColour{0.9, 0.2, 0.9};
// Range data's dots: light grey, apart from the landmarks' red. Points a fit
// set aside as outliers: orange and larger, to stand out from the data that
// shaped the surface, the green surface and the blue wireframe.
constexpr std::array<double, 3> kDataPoint{0.85, 0.85, 0.85};
constexpr std::array<double, 3> kOutlierPoint{1.0, 0.55, 0.0};
constexpr double kOutlierPixels = 5.0;
// The control mesh's wireframe, and in a creased mesh its creases.
constexpr std::array<double, 3> kWireframe{0.6, 0.7, 1.0};
constexpr std::array<unsigned char, 3> kCrease{255, 90, 40};
// The colour bar of colourByDistance at the right of its view.
vtkSmartPointer<vtkScalarBarActor> distanceBar(const DistanceColours& colours);
// Vertices drawn as round dots of a fixed size in pixels.
void pointsAsDots(vtkActor* actor, double pixels);

// The rows `rows` of `points` as vertices; with `selected` >= -1 they carry
// landmark colours (kLandmark, and kSelectedLandmark for row `selected`).
vtkSmartPointer<vtkPolyData> dots(const MatrixX3& points, const std::vector<int>& rows, int selected = -2);
// Every row of `points`.
std::vector<int> allRows(const MatrixX3& points);

// Adds `actor` drawing `points` to `renderer`: landmarks as dots coloured by
// their per-point colours (kLandmark, kSelectedLandmark); range data as small
// light grey dots; outliers set aside from it as orange ones.
void showLandmarks(vtkRenderer* renderer, vtkPolyData* points, vtkActor* actor);
void showDataPoints(vtkRenderer* renderer, vtkPolyData* points, vtkActor* actor);
void showOutliers(vtkRenderer* renderer, vtkPolyData* points, vtkActor* actor);

// A fixed-size window without multisampling, rendering off screen (figures:
// the same input gives the same pixels).
vtkSmartPointer<vtkRenderWindow> offScreenWindow(int width, int height);

enum class Corner { TopLeft, TopRight, BottomLeft, BottomRight, Left, Right, Top, Bottom };
// White text at a normalized viewport position, justified towards `corner`.
void cornerText(vtkTextActor* text, double x, double y, Corner corner, int fontSize = kFontSize);
// How many characters of cornerText's font at `fontSize` fit in `pixels`
// (Arial averages about 0.55 of its size a character), at least 20.
std::size_t textColumns(double pixels, int fontSize);

// The interactive windows' help: `help` in a dark box at (x, y), hidden
// until `h` shows it, added to `overlay`.
void helpOverlay(vtkRenderer* overlay, vtkTextActor* text, const char* help, double x, double y);

// Calls tick(client) at every timer event of `interactor` (the windows'
// redraw timers), through `command`.
void observeTimer(vtkRenderWindowInteractor* interactor, vtkCallbackCommand* command, void (*tick)(void* client),
                  void* client);

// A world point's display position in `renderer`: x and y in pixels, and
// its depth (0 near, 1 far), which worldAt takes back to the world.
Vector3 displayAt(vtkRenderer* renderer, const Vector3& world);
// The world point at display position (x, y) and depth `depth` in `renderer`.
Vector3 worldAt(vtkRenderer* renderer, double x, double y, double depth);

// The anatomical direction a unit LPS vector points to most: L, R, P, A, S or I.
std::string anatomicalLetter(const Vector3& direction);

}  // namespace dynsub::style
