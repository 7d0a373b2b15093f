#pragma once
// Writes a tessellated limit surface (Tessellation.h) in a format chosen by the
// file extension, so that ParaView, 3D Slicer and other tools open it:
//   .vtp  VTK XML polydata by VTK's writer (binary, LZ4 blocks): point data "Normals", cell data
//         "ElementType" (0 normal element, 1 special element) and "Element";
//   .vtk  legacy VTK polydata (binary): normals and point data, no cell data;
//   .obj  Wavefront OBJ with vertex normals;  .ply  binary PLY (float
//         positions and normals);  .stl  binary STL.
// Coordinates are written as given (mm). The file appears complete or not at all.
#include <cstdint>
#include <string>
#include <vector>

#include "dynsub/Tessellation.h"

namespace dynsub {

// A named value per point of the surface (e.g. a distance in mm), written as
// point data where the format has it (.vtp); the other formats leave it out.
struct PointScalars {
  std::string name;
  Eigen::VectorXd values;  // one per row of TriangleSurface::points, finite
  // When > 0, the value from which a point counts as far (mm), written in a
  // .vtp as the one-value field array farName(name) (SurfacePolyData.h), for
  // the figures to colour by (`dynsub render` redraws what the command drew).
  double far = 0.0;
};

// The point data a segmentation's surface carries: each point's distance to
// the nearest edge of the edge map (mm; -1 outside the region of interest,
// where it is unknown). The figures colour a surface that has it by it.
constexpr char kEdgeDistanceScalars[] = "edge_distance_mm";
// The point data a fitted surface carries: each point's distance to the
// nearest point of the scan (mm; SurfaceCoverage.h), far from the
// coverage's limit on: there the surface has no data under it.
constexpr char kScanDistanceScalars[] = "scan_distance_mm";

// `space`, when not empty, names the coordinate system of a .vtp as the
// field-data string array "SPACE" that 3D Slicer reads, and of a .vtk as
// "SPACE=" in its title line ("LPS" or "RAS"; Slicer assumes LPS without it). Throws dynsub::Error naming the file for
// an unknown extension or space, a missing or read-only directory, a failed write, scalars of the wrong size or not
// finite, or a far distance that is negative or not finite.
void writeTriangleSurface(const TriangleSurface& surface, const std::string& path,
                          const std::vector<PointScalars>& scalars = {}, const std::string& space = "");

// The memory writeTriangleSurface takes besides the surface, for `points` and
// `triangles` written to `path`: a .vtp goes through a copy in VTK's arrays;
// the other formats stream to the file.
std::uint64_t surfaceWriterBytes(const std::string& path, std::uint64_t points, std::uint64_t triangles);

// The extensions writeTriangleSurface accepts, with the dot (".vtp", ...).
std::vector<std::string> triangleSurfaceExtensions();

// Throws dynsub::Error naming `path` when writeTriangleSurface could not
// write it: an unknown extension, or a directory that is missing, read-only
// or a file. Commands call it before their work, so that a long evaluation
// does not end in a refusal of its output's name.
void requireTriangleSurfaceTarget(const std::string& path);

// Writes `points` as .xyz text (PointCloudIO.h reads it), one "x y z" line
// per point, with the digits that read back as the same doubles: points a
// program set aside can be matched exactly against the file they came from.
// Throws dynsub::Error naming `path` if it cannot be written; a failed
// write leaves no file.
void writePointCloudXyz(const MatrixX3& points, const std::string& path);

}  // namespace dynsub
