#pragma once
// Writes a tessellated limit surface (Tessellation.h) in a format chosen by the
// file extension, through VTK's writers so that ParaView, 3D Slicer and other
// tools open it:
//   .vtp  VTK XML polydata (binary, compressed): point data "Normals", cell data
//         "ElementType" (0 normal element, 1 special element) and "Element";
//   .obj  Wavefront OBJ with vertex normals;  .ply  binary PLY;  .stl  binary STL.
// Coordinates are written as given (mm). The file appears complete or not at all.
#include <string>
#include <vector>

#include "dynsub/Tessellation.h"

namespace dynsub {

// Throws dynsub::Error naming the file for an unknown extension, a missing or
// read-only directory, or a failed write.
void writeTriangleSurface(const TriangleSurface& surface, const std::string& path);

// The extensions writeTriangleSurface accepts, with the dot (".vtp", ...).
std::vector<std::string> triangleSurfaceExtensions();

}  // namespace dynsub
