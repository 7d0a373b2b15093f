#pragma once
// Point clouds (range data, landmarks as points) in mm, read by extension:
//   .xyz, .txt, .pwn  one point per line, the first three whitespace-separated
//               numbers (more columns, e.g. the normals of .pwn, points with
//               normals, are ignored); '#' comments
//   .csv        comma- or semicolon-separated, the first three columns; one
//               header line of names is skipped
//   .ply .off .obj  the vertices
//   .vtp        the points of VTK XML polydata
#include <string>

#include "dynsub/Types.h"

namespace dynsub {

struct PointCloud {
  MatrixX3 points;
  // The file is a surface mesh (it has faces): its points are vertices
  // someone placed on the surface, not a scanner's samples of it.
  bool meshVertices = false;
  // The genus of the file's surface where its faces make one closed,
  // connected, manifold and consistently oriented mesh; -1 otherwise (no
  // faces, a boundary, several pieces, or a defect MeshCheck.h names). A
  // model of another genus cannot follow it, and a fit's error, measured
  // from the points to the surface, does not see surface spanning a hole.
  int meshGenus = -1;
};

// Throws dynsub::Error naming the file (and line) for a missing, empty,
// truncated or malformed file or an unknown extension. Coordinates are not
// checked for finiteness here (see checkPointCloud in InitialModels.h).
PointCloud readPointCloud(const std::string& path);

}  // namespace dynsub
