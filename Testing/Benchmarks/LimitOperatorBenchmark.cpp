// Building and applying limit operators for the papers' 98-vertex cube after
// 0-3 global subdivisions (98, 386, 1538, 6146 control vertices), side by side
// with OpenSubdiv's LimitStencilTable (adaptive, isolation level 10, double) on
// the same points: 4 x 4 interior points per face, including the special
// elements. Reported: points per second (items/s).
//   build/bin/LimitOperatorBenchmark --benchmark_min_time=1
#include <memory>

#include <benchmark/benchmark.h>
#include <opensubdiv/far/stencilTableFactory.h>

#include "OpenSubdivReference.h"
#include "dynsub/ApplyOperator.h"
#include "dynsub/CatmullClark.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/StandardMeshes.h"

namespace {

using namespace OpenSubdiv;

dynsub::ControlMesh cubeAtLevel(int level) {
  dynsub::ControlMesh mesh = dynsub::makeCube98();
  for (int i = 0; i < level; ++i) mesh = dynsub::subdivide(mesh).mesh;
  return mesh;
}

std::vector<dynsub::SurfacePoint> samples(int faces) {
  std::vector<dynsub::SurfacePoint> points;
  for (int f = 0; f < faces; ++f)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) points.push_back({f, (i + 0.5) / 4, (j + 0.5) / 4});
  return points;
}

void DynSubBuildOperators(benchmark::State& state) {
  const dynsub::ControlMesh mesh = cubeAtLevel(static_cast<int>(state.range(0)));
  const std::vector<dynsub::SurfacePoint> points = samples(mesh.faceCount());
  for (auto _ : state) {
    const dynsub::LimitSurface surface(mesh);
    dynsub::LimitOperators ops = surface.operators(points, 1);  // J, J_u, J_v, as OpenSubdiv builds
    benchmark::DoNotOptimize(ops.J.nonZeros());
  }
  state.SetItemsProcessed(state.iterations() * points.size());
  state.counters["control_vertices"] = mesh.vertexCount();
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
  // Points come 16 per face, so one location array per face.
  for (const auto& p : points) {
    s.push_back(p.u);
    t.push_back(p.v);
  }
  Far::LimitStencilTableFactoryReal<double>::LocationArrayVec locations;
  for (size_t first = 0; first < points.size(); first += 16) {
    Far::LimitStencilTableFactoryReal<double>::LocationArray location;
    location.ptexIdx = points[first].face;
    location.numLocations = 16;
    location.s = &s[first];
    location.t = &t[first];
    locations.push_back(location);
  }
  return locations;
}

void OpenSubdivBuildStencils(benchmark::State& state) {
  const dynsub::ControlMesh mesh = cubeAtLevel(static_cast<int>(state.range(0)));
  const std::vector<dynsub::SurfacePoint> points = samples(mesh.faceCount());
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

BENCHMARK(DynSubBuildOperators)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(OpenSubdivBuildStencils)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(DynSubApplyOperators)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);
BENCHMARK(OpenSubdivApplyStencils)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
