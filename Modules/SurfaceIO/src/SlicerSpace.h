#pragma once
// 3D Slicer marks the coordinate system of the surfaces it writes as
// "SPACE=RAS" or "SPACE=LPS": in the header of a .vtk or .stl file, a comment
// of a .ply or .obj file, a field array SPACE of a .vtp file. A file without
// the mark is LPS, as Slicer reads it. DynSub reads in LPS, so a file marked
// RAS has its x and y negated on reading (a half turn about z, which keeps
// the polygons' orientation).
#include <string>

class vtkPolyData;

namespace dynsub {

// "RAS" or "LPS" where `text` holds the mark as a word of its own (not
// COLORSPACE=...), else empty: Slicer reads any other value as no mark.
std::string statedSpace(const std::string& text);

// The mark in the comment lines of a .ply's header or those an .obj begins
// with; empty for other extensions.
std::string commentSpace(const std::string& path);

// The mark in a .vtp's field array SPACE.
std::string fieldSpace(vtkPolyData* polyData);

}  // namespace dynsub
