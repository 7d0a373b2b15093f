#pragma once
// Point clouds (range data, landmarks as points) in mm, read by extension:
//   .xyz, .txt, .pwn  one point per line, the first three whitespace-separated
//               numbers (more columns, e.g. the normals of .pwn, points with
//               normals, are ignored); '#' comments
//   .csv        comma- or semicolon-separated, the first three columns; one
//               header line of names is skipped
//   .ply .off .obj  the vertices
//   .vtp        the points of VTK XML polydata
// In LPS: a .ply, .obj or .vtp file 3D Slicer marked "SPACE=RAS" has its x
// and y negated (SurfacePolyData.h reads surfaces so too).
#include <string>
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {

struct PointCloud {
  MatrixX3 points;
  // The file is a surface mesh (it has faces): its points are vertices
  // someone placed on the surface, not a scanner's samples of it.
  bool meshVertices = false;
  // Its polygons, vertex indices from 0 (.off, .obj, .ply, and a .vtp's
  // polys); empty for a cloud.
  std::vector<std::vector<int>> faces;
  // The coordinate system the file states as 3D Slicer marks it ("RAS",
  // "LPS", empty for none); the points are LPS whatever it says.
  std::string space;
};

// Throws dynsub::Error naming the file (and line) for a missing, empty,
// truncated or malformed file or an unknown extension. Coordinates are not
// checked for finiteness here (see checkPointCloud in InitialModels.h).
PointCloud readPointCloud(const std::string& path);

// The genus of `cloud`'s faces where they make one closed, connected,
// manifold and consistently oriented mesh (points no face uses aside); -1
// otherwise: no faces, a boundary, several pieces, or a defect MeshCheck.h
// names. A model of another genus cannot take the scan's shape, and a fit's
// error, measured from the points to the surface, does not see surface
// where the scan has none. Checks and builds the mesh (MeshCheck.h,
// Topology.h): about 0.3 s of CPU for the bunny's 75,408 triangles, so only
// `fit` asks.
int closedMeshGenus(const PointCloud& cloud, const std::string& source);

}  // namespace dynsub
