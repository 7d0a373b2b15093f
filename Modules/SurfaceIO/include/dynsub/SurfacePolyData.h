#pragma once
// The tessellated limit surface as VTK polydata, the form SurfaceWriter.h
// writes and the Visualization module draws: triangles with point data
// "Normals" and cell data "ElementType" (0 normal element, 1 special element)
// and "Element". Coordinates in mm (LPS for images).
#include <string>

#include <vtkSmartPointer.h>

#include "dynsub/Tessellation.h"

class vtkPolyData;

namespace dynsub {

vtkSmartPointer<vtkPolyData> toPolyData(const TriangleSurface& surface);

// Adds `values` (one per point of `polyData`, the caller's to check) as the
// point-data array `name`, in doubles.
void addPointData(vtkPolyData* polyData, const std::string& name, const Eigen::VectorXd& values);
// The field array that holds, beside the point-data array `scalars`, the
// value from which a point counts as far: scalars + "_far".
std::string farName(const std::string& scalars);
// Adds `far` as the one-value field array farName(name).
void addFarDistance(vtkPolyData* polyData, const std::string& name, double far);

// Reads a triangle surface (.vtp, .vtk, .obj, .ply or .stl, by extension; .obj
// through DynSub's own reader, MeshIO.h, which names a bad record's line), in
// LPS: a file 3D Slicer marked "SPACE=RAS" is turned into LPS. Throws
// dynsub::Error naming the file when it is missing, unreadable, has no
// triangles, or has non-finite coordinates.
vtkSmartPointer<vtkPolyData> readSurfacePolyData(const std::string& path);

// The points of `polyData`, mm.
MatrixX3 pointsOf(vtkPolyData* polyData);

// The points of readSurfacePolyData's surface.
MatrixX3 readSurfacePoints(const std::string& path);

}  // namespace dynsub
