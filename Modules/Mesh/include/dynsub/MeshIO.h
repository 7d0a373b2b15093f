#pragma once
// Control mesh files. Reading: Wavefront OBJ (v and f records; v/vt/vn and
// negative indices accepted, other records ignored), OFF, and PLY (ascii and
// binary, either byte order; element "vertex" with x, y, z and element "face"
// with a "vertex_indices" list). Writing: OBJ with round-trip precision.
#include <string>
#include <vector>

#include "dynsub/ControlMesh.h"

namespace dynsub {

struct PolygonData {
  MatrixX3 points;
  std::vector<Polygon> faces;
};

// Parses the file by extension (.obj, .off, .ply; case-insensitive) without
// checking mesh validity. Throws dynsub::Error naming the file and, where it
// helps, the line of a missing, unreadable, truncated or malformed file.
PolygonData readPolygonData(const std::string& path);

// readPolygonData + checks (MeshCheck.h): the usual way to load a control mesh.
ControlMesh readControlMesh(const std::string& path);

// Writes an OBJ file atomically (complete or not at all).
void writeObj(const ControlMesh& mesh, const std::string& path);

}  // namespace dynsub
