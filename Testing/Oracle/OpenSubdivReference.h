#pragma once
// OpenSubdiv's limit surface at given Ptex locations, in double precision, with
// the boundary rules DynSub uses (boundary edges and corners sharp). A test
// oracle only: DynSub does not use OpenSubdiv.
#include <vector>

#include "dynsub/ControlMesh.h"
#include "dynsub/LimitSurface.h"

namespace dynsub::testing {

struct ReferenceSample {
  Vector3 position, du, dv;
};

// isolationLevel: OpenSubdiv's adaptive refinement depth (at most 10); points
// within 2^-isolationLevel of an extraordinary vertex lie on its end-cap patches.
std::vector<ReferenceSample> openSubdivLimit(const ControlMesh& mesh, const std::vector<SurfacePoint>& points,
                                             int isolationLevel = 10);

}  // namespace dynsub::testing
