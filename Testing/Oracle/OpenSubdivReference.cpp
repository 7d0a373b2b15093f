#include "OpenSubdivReference.h"

#include <memory>

#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

namespace dynsub::testing {

using namespace OpenSubdiv;

std::unique_ptr<Far::TopologyRefiner> openSubdivRefiner(const ControlMesh& mesh) {
  std::vector<int> faceSizes, faceVertices;
  for (const Polygon& face : mesh.faces()) {
    faceSizes.push_back(static_cast<int>(face.size()));
    faceVertices.insert(faceVertices.end(), face.begin(), face.end());
  }
  Far::TopologyDescriptor descriptor;
  descriptor.numVertices = mesh.vertexCount();
  descriptor.numFaces = static_cast<int>(faceSizes.size());
  descriptor.numVertsPerFace = faceSizes.data();
  descriptor.vertIndicesPerFace = faceVertices.data();
  std::vector<int> creaseEnds;
  std::vector<float> creaseSharpness;
  for (const Crease& crease : mesh.creases()) {
    creaseEnds.insert(creaseEnds.end(), {crease.a, crease.b});
    creaseSharpness.push_back(static_cast<float>(crease.sharpness));
  }
  descriptor.numCreases = static_cast<int>(creaseSharpness.size());
  descriptor.creaseVertexIndexPairs = creaseEnds.data();
  descriptor.creaseWeights = creaseSharpness.data();
  Sdc::Options rules;
  rules.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  // The factory copies the topology, so the arrays may go out of scope.
  return std::unique_ptr<Far::TopologyRefiner>(
      Factory::Create(descriptor, Factory::Options(Sdc::SCHEME_CATMARK, rules)));
}

std::vector<ReferenceSample> openSubdivLimit(const ControlMesh& mesh, const std::vector<SurfacePoint>& points,
                                             int isolationLevel) {
  std::unique_ptr<Far::TopologyRefiner> refiner = openSubdivRefiner(mesh);
  // Infinitely sharp creases as boundary patches, exact, rather than isolated
  // to the deepest level and approximated there by end caps (2^-10 of the
  // patch's size off).
  Far::TopologyRefiner::AdaptiveOptions options(isolationLevel);
  options.useInfSharpPatch = true;
  refiner->RefineAdaptive(options);

  // One location array per point keeps the bookkeeping trivial.
  std::vector<double> s(points.size()), t(points.size());
  Far::LimitStencilTableFactoryReal<double>::LocationArrayVec locations;
  for (size_t i = 0; i < points.size(); ++i) {
    s[i] = points[i].u;
    t[i] = points[i].v;
    Far::LimitStencilTableFactoryReal<double>::LocationArray location;
    location.ptexIdx = points[i].face;
    location.numLocations = 1;
    location.s = &s[i];
    location.t = &t[i];
    locations.push_back(location);
  }
  std::unique_ptr<const Far::LimitStencilTableReal<double>> table(
      Far::LimitStencilTableFactoryReal<double>::Create(*refiner, locations));

  const MatrixX3 control = mesh.points();
  std::vector<ReferenceSample> result(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Far::LimitStencilReal<double> stencil = table->GetLimitStencil(static_cast<Far::Index>(i));
    ReferenceSample& sample = result[i];
    sample.position.setZero();
    sample.du.setZero();
    sample.dv.setZero();
    for (int k = 0; k < stencil.GetSize(); ++k) {
      const Vector3 p = control.row(stencil.GetVertexIndices()[k]).transpose();
      sample.position += stencil.GetWeights()[k] * p;
      sample.du += stencil.GetDuWeights()[k] * p;
      sample.dv += stencil.GetDvWeights()[k] * p;
    }
  }
  return result;
}

}  // namespace dynsub::testing
