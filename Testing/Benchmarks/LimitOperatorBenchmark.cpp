// Building and applying limit operators for the papers' 98-vertex cube after
// 0-3 global subdivisions (98, 386, 1538, 6146 control vertices), side by side
// with OpenSubdiv's LimitStencilTable (adaptive, isolation level 10, double) on
// the same points: 4 x 4 interior points per face, including the special
// elements. Reported: points per second (items/s).
// The *Triangles pair builds the same for a scan-like control mesh, a sphere
// of triangles (an icosahedron split 3-5 times: 642, 2562, 10242 vertices),
// one point per parametric face: every vertex of it is extraordinary, so it
// needs two isolating subdivisions and half its elements are special.
// Tessellate and FindSelfIntersections: the output tessellation of the cube
// at levels 0-2 (8 x 8 squares per face; level 1 gives the 49,152 triangles of
// a segmented structure), and the search for its crossing triangles that
// every model-moving command runs on it, side by side.
//   build/bin/LimitOperatorBenchmark --benchmark_min_time=1
#include <array>
#include <cmath>
#include <map>
#include <memory>

#include <benchmark/benchmark.h>
#include <opensubdiv/far/stencilTableFactory.h>

#include "OpenSubdivReference.h"
#include "dynsub/ApplyOperator.h"
#include "dynsub/CatmullClark.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/SelfIntersection.h"
#include "dynsub/StandardMeshes.h"

namespace {

using namespace OpenSubdiv;

dynsub::ControlMesh cubeAtLevel(int level) {
  dynsub::ControlMesh mesh = dynsub::makeCube98();
  for (int i = 0; i < level; ++i) mesh = dynsub::subdivide(mesh).mesh;
  return mesh;
}

// The icosahedron with each triangle split into four `splits` times, its
// vertices on the unit sphere.
dynsub::ControlMesh triangleSphere(int splits) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<dynsub::Vector3> points = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int split = 0; split < splits; ++split) {
    std::map<std::pair<int, int>, int> midpoints;
    const auto midpoint = [&](int a, int b) {
      const auto [it, added] = midpoints.try_emplace({std::min(a, b), std::max(a, b)}, static_cast<int>(points.size()));
      if (added) points.push_back(0.5 * (points[a] + points[b]));
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& [a, b, c] : triangles) {
      const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      finer.insert(finer.end(), {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}});
    }
    triangles = std::move(finer);
  }
  dynsub::MatrixX3 positions(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t i = 0; i < points.size(); ++i) positions.row(static_cast<Eigen::Index>(i)) = points[i].normalized();
  std::vector<dynsub::Polygon> faces;
  for (const auto& [a, b, c] : triangles) faces.push_back({a, b, c});
  return dynsub::ControlMesh::fromPolygons(positions, faces);
}

// One point per parametric face (three per triangle), at its middle.
std::vector<dynsub::SurfacePoint> parametricFaceMiddles(const dynsub::LimitSurface& surface) {
  std::vector<dynsub::SurfacePoint> points;
  for (int f = 0; f < surface.parametricFaceCount(); ++f) points.push_back({f, 0.5, 0.5});
  return points;
}

std::vector<dynsub::SurfacePoint> samples(int faces) {
  std::vector<dynsub::SurfacePoint> points;
  for (int f = 0; f < faces; ++f)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) points.push_back({f, (i + 0.5) / 4, (j + 0.5) / 4});
  return points;
}

// DynSub's limit surface and operators for the points, timed.
void timeDynSubBuild(benchmark::State& state, const dynsub::ControlMesh& mesh,
                     const std::vector<dynsub::SurfacePoint>& points) {
  for (auto _ : state) {
    const dynsub::LimitSurface surface(mesh);
    dynsub::LimitOperators ops = surface.operators(points, 1);  // J, J_u, J_v, as OpenSubdiv builds
    benchmark::DoNotOptimize(ops.J.nonZeros());
  }
  state.SetItemsProcessed(state.iterations() * points.size());
  state.counters["control_vertices"] = mesh.vertexCount();
}

void DynSubBuildOperators(benchmark::State& state) {
  const dynsub::ControlMesh mesh = cubeAtLevel(static_cast<int>(state.range(0)));
  timeDynSubBuild(state, mesh, samples(mesh.faceCount()));
}

void DynSubApplyOperators(benchmark::State& state) {
  const dynsub::ControlMesh mesh = cubeAtLevel(static_cast<int>(state.range(0)));
  const dynsub::LimitSurface surface(mesh);
  const dynsub::LimitOperators ops = surface.operators(samples(mesh.faceCount()), 1);  // J, J_u, J_v
  const dynsub::MatrixX3 control = mesh.points();
  // Into arrays allocated once, as OpenSubdiv's side below writes into its own.
  dynsub::MatrixX3 s, su, sv;
  for (auto _ : state) {
    dynsub::applyOperators(ops.J, ops.Ju, ops.Jv, control, s, su, sv);
    benchmark::DoNotOptimize(s.data());
    benchmark::DoNotOptimize(su.data());
    benchmark::DoNotOptimize(sv.data());
  }
  state.SetItemsProcessed(state.iterations() * ops.J.rows());
}

Far::LimitStencilTableFactoryReal<double>::LocationArrayVec locationsOf(const std::vector<dynsub::SurfacePoint>& points,
                                                                        std::vector<double>& s, std::vector<double>& t) {
  // One location array per run of points on one face.
  for (const auto& p : points) {
    s.push_back(p.u);
    t.push_back(p.v);
  }
  Far::LimitStencilTableFactoryReal<double>::LocationArrayVec locations;
  for (size_t first = 0, end = 0; first < points.size(); first = end) {
    for (end = first + 1; end < points.size() && points[end].face == points[first].face;) ++end;
    Far::LimitStencilTableFactoryReal<double>::LocationArray location;
    location.ptexIdx = points[first].face;
    location.numLocations = static_cast<int>(end - first);
    location.s = &s[first];
    location.t = &t[first];
    locations.push_back(location);
  }
  return locations;
}

// OpenSubdiv's adaptive refinement and limit stencils for the points, timed.
void timeOpenSubdivBuild(benchmark::State& state, const dynsub::ControlMesh& mesh,
                         const std::vector<dynsub::SurfacePoint>& points) {
  std::vector<double> s, t;
  const auto locations = locationsOf(points, s, t);
  for (auto _ : state) {
    auto refiner = dynsub::testing::openSubdivRefiner(mesh);
    refiner->RefineAdaptive(Far::TopologyRefiner::AdaptiveOptions(10));
    std::unique_ptr<const Far::LimitStencilTableReal<double>> table(
        Far::LimitStencilTableFactoryReal<double>::Create(*refiner, locations));
    benchmark::DoNotOptimize(table->GetNumStencils());
  }
  state.SetItemsProcessed(state.iterations() * points.size());
}

void OpenSubdivBuildStencils(benchmark::State& state) {
  const dynsub::ControlMesh mesh = cubeAtLevel(static_cast<int>(state.range(0)));
  timeOpenSubdivBuild(state, mesh, samples(mesh.faceCount()));
}

void OpenSubdivApplyStencils(benchmark::State& state) {
  const dynsub::ControlMesh mesh = cubeAtLevel(static_cast<int>(state.range(0)));
  const std::vector<dynsub::SurfacePoint> points = samples(mesh.faceCount());
  std::vector<double> s, t;
  const auto locations = locationsOf(points, s, t);
  auto refiner = dynsub::testing::openSubdivRefiner(mesh);
  refiner->RefineAdaptive(Far::TopologyRefiner::AdaptiveOptions(10));
  std::unique_ptr<const Far::LimitStencilTableReal<double>> table(
      Far::LimitStencilTableFactoryReal<double>::Create(*refiner, locations));
  const dynsub::MatrixX3 control = mesh.points();
  struct Point {
    double p[3];
    void Clear() { p[0] = p[1] = p[2] = 0; }
    void AddWithWeight(const Point& o, double w) {
      p[0] += w * o.p[0];
      p[1] += w * o.p[1];
      p[2] += w * o.p[2];
    }
  };
  std::vector<Point> in(control.rows()), out(points.size()), du(points.size()), dv(points.size());
  for (Eigen::Index i = 0; i < control.rows(); ++i) in[i] = Point{{control(i, 0), control(i, 1), control(i, 2)}};
  for (auto _ : state) {
    table->UpdateValues(in.data(), out.data());
    table->UpdateDerivs(in.data(), du.data(), dv.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * points.size());
}

void DynSubBuildOperatorsTriangles(benchmark::State& state) {
  const dynsub::ControlMesh mesh = triangleSphere(static_cast<int>(state.range(0)));
  timeDynSubBuild(state, mesh, parametricFaceMiddles(dynsub::LimitSurface(mesh)));
}

void OpenSubdivBuildStencilsTriangles(benchmark::State& state) {
  const dynsub::ControlMesh mesh = triangleSphere(static_cast<int>(state.range(0)));
  timeOpenSubdivBuild(state, mesh, parametricFaceMiddles(dynsub::LimitSurface(mesh)));
}

void Tessellate(benchmark::State& state) {
  const dynsub::ControlMesh mesh = cubeAtLevel(static_cast<int>(state.range(0)));
  const dynsub::LimitSurface surface(mesh);
  for (auto _ : state)
    benchmark::DoNotOptimize(dynsub::tessellate(surface, mesh.points(), dynsub::kOutputSegments).points.data());
}

void FindSelfIntersections(benchmark::State& state) {
  const dynsub::ControlMesh mesh = cubeAtLevel(static_cast<int>(state.range(0)));
  const dynsub::TriangleSurface tessellation =
      dynsub::tessellate(dynsub::LimitSurface(mesh), mesh.points(), dynsub::kOutputSegments);
  for (auto _ : state) {
    const dynsub::SelfIntersection found = dynsub::findSelfIntersections(tessellation);
    if (found.trianglePairs != 0) state.SkipWithError("the cube's limit surface crosses itself");
  }
  state.counters["triangles"] = static_cast<double>(tessellation.triangles.size());
}

BENCHMARK(DynSubBuildOperators)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(OpenSubdivBuildStencils)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(DynSubApplyOperators)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);
BENCHMARK(OpenSubdivApplyStencils)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);
BENCHMARK(DynSubBuildOperatorsTriangles)->DenseRange(3, 5)->Unit(benchmark::kMillisecond);
BENCHMARK(OpenSubdivBuildStencilsTriangles)->DenseRange(3, 5)->Unit(benchmark::kMillisecond);
BENCHMARK(Tessellate)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(FindSelfIntersections)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
