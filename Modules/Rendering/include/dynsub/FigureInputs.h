#pragma once
// The figures of a result as the commands ask for them (Figures.h draws
// them), in the project's own types: the commands hold no VTK object, and
// their sources compile without VTK's headers.
#include <string>

#include "dynsub/ConvergenceHistory.h"
#include "dynsub/Tessellation.h"
#include "dynsub/Types.h"

namespace dynsub {

class ControlMesh;
struct Volume;

// The coordinates figures print: LPS (x to the left, y posterior, z superior:
// DICOM's, ITK's and the tool's own) or RAS (x and y negated: NIfTI's world,
// FreeSurfer's, MNI's). The figures name the one they use.
enum class FigureCoordinates { Lps, Ras };
std::string coordinatesName(FigureCoordinates coordinates);  // "LPS" or "RAS"

// A surface coloured by a distance of each point, held in its point array
// `array` (mm; -1 unknown): green up to `near`, through yellow, to magenta
// at `far` and beyond, grey where unknown. The colour bar reads "mm to " +
// `to`; the slices' legend, "contour on " + `on` (or "contour within N mm
// of " + `on`) and "contour F mm or more from " + `from`.
struct DistanceColours {
  std::string array;
  double near = 0.0, far = 0.0;  // mm, 0 <= near < far
  std::string to, on, from;
};
// A segmentation's distance to the image's edges (kEdgeDistanceScalars,
// SurfaceWriter.h), magenta from style::kFarFromEdges on: where it is held by
// the edges and where by tension and landmarks alone.
DistanceColours edgeDistanceColours();
// A fit's distance to its scan (kScanDistanceScalars), magenta from `far` on,
// the coverage's limit (SurfaceCoverage::limit): where the surface has no
// points near it. Green up to half of it, so that the distances between the
// points of a sparse scan, which are well below, do not mottle a covered
// surface.
DistanceColours scanDistanceColours(double far);

// The figures of a result, for callers that hold no VTK object (the commands).
// Not owned; the surface is `surface`, or else read from `surfaceFile`.
struct FigureInputs {
  const TriangleSurface* surface = nullptr;
  std::string surfaceFile;                   // any file SurfacePolyData.h reads
  const Volume* image = nullptr;             // optional
  std::string imageFile;                     // the image's file, for messages (optional)
  const ControlMesh* controlMesh = nullptr;  // optional wireframe, 3D figure only
  MatrixX3 landmarks;                        // #landmarks x 3, LPS mm
  MatrixX3 dataPoints;                       // range data, mm
  MatrixX3 outliers;                         // range data set aside as outliers (fit), mm
  const ConvergenceHistory* history = nullptr;  // needed for the convergence figure
  // Per point of `surface`: its distance to the nearest edge (mm, -1
  // unknown), to colour it by (edgeDistanceColours()); empty: none. A
  // surface read from `surfaceFile` is coloured by the same array if it has it.
  Eigen::VectorXd edgeDistances;
  // Per point of `surface`: its distance to the range data (mm), to colour it
  // by (scanDistanceColours(scanDistanceFar)); empty: none. A surface read
  // from `surfaceFile` is coloured by its scan_distance_mm array if it also
  // has the far distance beside it (farName, SurfacePolyData.h).
  Eigen::VectorXd scanDistances;
  double scanDistanceFar = 0.0;
  FigureCoordinates coordinates = FigureCoordinates::Lps;
};
// The figures' file formats. PNG is a raster. In PDF and SVG the text (the
// captions, the legend, the plot's labels) is vector outlines, and so are
// the plot's axes and curves; the image, the surface, its contours and the
// landmarks are a raster at the figure's resolution.
enum class FigureFormat { Png, Pdf, Svg };
std::string figureExtension(FigureFormat format);  // "png", "pdf" or "svg"

// Each figure has a nominal size (slices 12 x 8 in, the 3D view 8 x 8 in,
// the convergence plot 9 x 5 in) and is drawn at `dpi` pixels per inch of it:
// at the default, 1200 x 800 pixels for the slices. Text, lines and dots grow
// with the resolution, so a figure looks the same at any dpi, only sharper.
constexpr double kDefaultFigureDpi = 100.0;
constexpr double kMinFigureDpi = 50.0, kMaxFigureDpi = 600.0;

// The paths to write the slices, the 3D view and the convergence plot to
// (slices.png, surface3d.png, convergence.png for PNG); an empty path is not
// rendered. Needs a display (figureDisplay). Throws dynsub::Error as the
// figures do, and naming a file that could not be written.
// PDF and SVG are drawn by VTK's GL2PS exporter and rewritten at the nominal
// size by pdftocairo (Debian's poppler-utils).
struct FigureFiles {
  std::string slices, surface3d, convergence;
  FigureFormat format = FigureFormat::Png;
  double dpi = kDefaultFigureDpi;
};
void writeFigures(const FigureInputs& inputs, const FigureFiles& files);
// Throws dynsub::Error, naming the package, when `format` needs a program
// that is not installed (pdftocairo for PDF and SVG): for commands to call
// before their long part.
void requireFigureFormat(FigureFormat format);

// True when an X display can be opened; otherwise `why` says what is missing.
bool displayAvailable(std::string* why = nullptr);

// For writing figures: the X display, or, when DISPLAY is not set (a cluster
// node, a batch job), a private virtual X server (Xvfb, 1280x1024x24, no TCP)
// started for this process on a free display number and stopped when the
// process ends. False, with `why`, when neither works (no xvfb package).
// The display is made ready once (prepareFigureDisplay) and the answer kept
// for the rest of the process.
bool figureDisplay(std::string* why = nullptr);

// What figureDisplay() needs, made ready on a second thread while the caller
// goes on: the private X server started when DISPLAY is not set, and the
// OpenGL driver loaded (for Mesa's software renderer, loading it and LLVM
// takes longer than rendering a figure). Call it once a run knows it will
// write figures, as early as it can; figureDisplay() then waits for it and
// answers as it would have. DISPLAY is set by figureDisplay(), on the
// caller's thread, never by the second one.
void prepareFigureDisplay();

}  // namespace dynsub
