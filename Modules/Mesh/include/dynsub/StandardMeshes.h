#pragma once
// The initial control meshes of the papers (TVCG 1998 §4, ICCV 1998 §4), also
// stored in Data/Meshes/ as OBJ files written by `dynsub mesh`.
#include <string>
#include <vector>

#include "dynsub/ControlMesh.h"

namespace dynsub {

// The cube [-1,1]^3 with 4 x 4 quads on each side: 98 vertices, 96 faces; its 8
// corners are extraordinary vertices of valence 3 (ICCV 1998 §4).
ControlMesh makeCube98();
// A torus of 8 x 4 quads around the z axis (major radius 1, minor radius 0.5):
// 32 vertices, 32 faces, all of valence 4 (TVCG 1998 Fig. 6).
ControlMesh makeTorus32();
// The flat sheet [-1,1]^2 at z = 0 with 8 x 8 quads: 81 vertices, 64 faces,
// normal +z, with a boundary and four valence-2 corners (TVCG 1998 Fig. 6).
ControlMesh makeSheet81();

// "cube", "torus" or "sheet"; throws dynsub::Error for any other name.
ControlMesh makeStandardMesh(const std::string& name);
std::vector<std::string> standardMeshNames();

}  // namespace dynsub
