#pragma once
// Control mesh files. Reading: Wavefront OBJ (v and f records; v/vt/vn and
// negative indices accepted; crease tags as OpenSubdiv writes them,
// "t crease 2/1/0 a b sharpness" with vertices numbered from 0; other tags
// refused, other records ignored), OFF, and PLY (ascii and binary, either byte
// order; element "vertex" with x, y, z and element "face" with a
// "vertex_indices" list). Writing: OBJ with round-trip precision and the
// mesh's crease tags.
//
// The readers are DynSub's own rather than OpenMesh::IO because a control
// mesh must survive a round trip exactly and a bad record must be refused:
// OpenMesh 9's OBJ reader keeps coordinates as float (0.12345678901234567
// comes back as 0.12345679104328156), drops a vertex it cannot parse and the
// faces that use it with only a line on its log, and splits the faces of a
// non-manifold edge onto copies of their vertices.
#include <string>
#include <vector>

#include "dynsub/ControlMesh.h"

namespace dynsub {

struct PolygonData {
  MatrixX3 points;
  std::vector<Polygon> faces;
  std::vector<Crease> creases;
  // Where the file's numbering of vertices and faces starts: 1 for OBJ, 0 for
  // OFF and PLY (its messages, and the checks', count as the file does).
  int firstNumber = 0;
};

// Parses the file by extension (.obj, .off, .ply; case-insensitive) without
// checking mesh validity. Throws dynsub::Error naming the file and, where it
// helps, the line of a missing, unreadable, truncated or malformed file.
PolygonData readPolygonData(const std::string& path);

// readPolygonData + checks (MeshCheck.h): the usual way to load a control mesh.
ControlMesh readControlMesh(const std::string& path);

// Writes an OBJ file atomically (complete or not at all); `path` must end in .obj.
void writeObj(const ControlMesh& mesh, const std::string& path);

}  // namespace dynsub
