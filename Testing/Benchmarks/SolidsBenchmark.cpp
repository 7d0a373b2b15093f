// Update time per step of dynamic subdivision solids (SolidDynamics.h) for
// the Table 1 models DynSub rebuilds, with the rope tool pulling a corner
// (as when sculpting); and the time a topology change takes while sculpting
// (Sculpting.h: extrude rebuilds the model). Run: build/bin/SolidsBenchmark
#include <benchmark/benchmark.h>

#include <memory>

#include "dynsub/Sculpting.h"
#include "dynsub/SolidDynamics.h"

namespace {

dynsub::Lattice model(int which) {
  if (which == 0) return dynsub::regularLattice(2, 2, 2);                                  // Cube (3^3)
  if (which == 1) return dynsub::regularLattice(3, 3, 3);                                  // Cube (4^3)
  return dynsub::regularLattice(3, 3, 3, 1.0, {13, 4, 22, 10, 16, 12, 14});               // Cube w/ holes
}

void SolidStep(benchmark::State& state) {
  dynsub::SolidModel solid(model(static_cast<int>(state.range(0))), static_cast<int>(state.range(1)));
  solid.rope(solid.nearestDataPoint(dynsub::Vector3(3, 3, 3)), dynsub::Vector3(4, 4, 4), 40.0);
  for (auto _ : state) solid.step(0.01);
  state.counters["mass_points"] = solid.dataLattice().pointCount();
  state.counters["control_points"] = solid.control().pointCount();
}

// Extruding a top face of the model: subdividing the new lattice, building its
// springs and factoring its mass matrix (the pause a sculptor sees).
void SculptExtrude(benchmark::State& state) {
  dynsub::SculptSettings settings;
  settings.levels = static_cast<int>(state.range(1));
  const dynsub::Lattice lattice = model(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    state.PauseTiming();
    auto sculpture = std::make_unique<dynsub::Sculpture>(lattice, settings);
    const int face = sculpture->boundaryFaceNear(dynsub::Vector3(0.5, 0.5, 10));
    state.ResumeTiming();
    sculpture->extrude(face);
    benchmark::DoNotOptimize(sculpture->model().controlPoints().data());
    state.PauseTiming();
    sculpture.reset();  // not the extrusion's cost
    state.ResumeTiming();
  }
}

}  // namespace

// Args: model (0 Cube 3^3, 1 Cube 4^3, 2 Cube w/ holes), subdivision level.
BENCHMARK(SolidStep)->Args({0, 2})->Args({0, 3})->Args({1, 1})->Args({1, 2})->Args({2, 2})
    ->Unit(benchmark::kMillisecond);

BENCHMARK(SculptExtrude)->Args({0, 2})->Args({0, 3})->Args({1, 2})->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
