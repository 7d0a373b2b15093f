#pragma once
// OpenSubdiv's limit surface at given Ptex locations, in double precision, with
// the boundary rules DynSub uses (boundary edges and corners sharp) and the
// mesh's creases (OpenSubdiv's uniform sharpness rule). A test oracle only:
// DynSub does not use OpenSubdiv.
#include <memory>
#include <vector>

#include <opensubdiv/far/topologyRefiner.h>

#include "dynsub/ControlMesh.h"
#include "dynsub/LimitSurface.h"

namespace dynsub::testing {

struct ReferenceSample {
  Vector3 position, du, dv;
};

// An OpenSubdiv refiner for the mesh's topology with DynSub's boundary rules
// (Catmull-Clark; boundary edges and corners sharp) and its creases, not yet refined.
std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> openSubdivRefiner(const ControlMesh& mesh);

// isolationLevel: OpenSubdiv's adaptive refinement depth (at most 10); points
// within 2^-isolationLevel of an extraordinary vertex lie on its end-cap patches.
std::vector<ReferenceSample> openSubdivLimit(const ControlMesh& mesh, const std::vector<SurfacePoint>& points,
                                             int isolationLevel = 10);

}  // namespace dynsub::testing
