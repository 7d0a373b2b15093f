// Speed of the dynamics for the papers' initial model (the 98-vertex cube) at
// levels 0-3 (98, 386, 1538, 6146 control vertices): assembly of M, D, K; one
// time step (force stiffness frozen, Integrator.h) with each linear solver,
// including the factorization or preconditioner set-up, measured separately;
// one Newton direction of the static scheme from a new solver (its matrix's
// pattern, ordering and factorization: the springs to the nearest points with
// their tangent-plane stiffness, StaticSolver.h); and time to equilibrium of a
// pure-spring problem (springs to a sphere around the cube, attached once).
// Run: build/bin/DynamicsBenchmark
#include <benchmark/benchmark.h>

#include "dynsub/CatmullClark.h"
#include "dynsub/ForceModel.h"
#include "dynsub/Integrator.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/PhysicalMatrices.h"
#include "dynsub/Simulation.h"
#include "dynsub/StaticSolver.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

ControlMesh cubeAtLevel(int level) {
  ControlMesh mesh = makeCube98();
  for (int i = 0; i < level; ++i) mesh = subdivide(mesh).mesh;
  return mesh;
}

double elementSize(int level) { return std::ldexp(1.0, -level); }

// Targets: the cube's limit surface pushed out onto a sphere of radius 1.2.
MatrixX3 sphereTargets(const LimitSurface& surface, const MatrixX3& points) {
  MatrixX3 targets = tessellate(surface, points, 2).points;
  for (Eigen::Index i = 0; i < targets.rows(); ++i) targets.row(i) *= 1.2 / targets.row(i).norm();
  return targets;
}

LinearSolver solverOf(int64_t i) {
  return i == 0 ? LinearSolver::Cholesky : i == 1 ? LinearSolver::ConjugateGradient
                                                  : LinearSolver::PreconditionedConjugateGradient;
}

void BM_Assembly(benchmark::State& state) {
  const ControlMesh mesh = cubeAtLevel(static_cast<int>(state.range(0)));
  const LimitSurface surface(mesh);
  AssemblyOptions options;
  options.elementSize = elementSize(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(assemblePhysicalMatrices(surface, Material{}, options));
  state.counters["control_vertices"] = mesh.vertexCount();
}
BENCHMARK(BM_Assembly)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

struct StepProblem {
  ControlMesh mesh;
  std::unique_ptr<LimitSurface> surface;
  PhysicalMatrices matrices;
  SymmetricMatrix stabilizing;
  MatrixX3 force;

  explicit StepProblem(int level) : mesh(cubeAtLevel(level)), surface(std::make_unique<LimitSurface>(mesh)) {
    AssemblyOptions options;
    options.elementSize = elementSize(level);
    matrices = assemblePhysicalMatrices(*surface, Material{}, options);
    const MatrixX3 points = mesh.points();
    const MatrixX3 targets = sphereTargets(*surface, points);
    SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 100.0 * 96 / targets.rows()),
                             SpringForceModel::Attach::NearestAtLevelStart);
    SurfaceQuadrature none;
    springs.beginLevel(*surface, none, points);
    stabilizing = SymmetricMatrix(springs.stabilizingStiffness(points));
    double potential = 0.0;
    force = springs.generalizedForce(points, potential);
  }
};

void BM_SolverSetup(benchmark::State& state) {
  const StepProblem problem(static_cast<int>(state.range(0)));
  IntegratorOptions options;
  options.solver = solverOf(state.range(1));
  for (auto _ : state) benchmark::DoNotOptimize(Integrator(problem.matrices, problem.stabilizing, {}, options));
  state.counters["control_vertices"] = problem.mesh.vertexCount();
}

void BM_Step(benchmark::State& state) {
  const StepProblem problem(static_cast<int>(state.range(0)));
  IntegratorOptions options;
  options.solver = solverOf(state.range(1));
  Integrator integrator(problem.matrices, problem.stabilizing, {}, options);
  const MatrixX3 p = problem.mesh.points();
  for (auto _ : state) benchmark::DoNotOptimize(integrator.step(p, p, problem.force));
  state.counters["control_vertices"] = problem.mesh.vertexCount();
  state.counters["solver_iterations"] = integrator.lastIterations();
}

void BM_NewtonDirection(benchmark::State& state) {
  const int level = static_cast<int>(state.range(0));
  const ControlMesh mesh = cubeAtLevel(level);
  const LimitSurface surface(mesh);
  AssemblyOptions assembly;
  assembly.elementSize = elementSize(level);
  const PhysicalMatrices matrices = assemblePhysicalMatrices(surface, Material{}, assembly);
  const MatrixX3 points = mesh.points();
  const MatrixX3 targets = sphereTargets(surface, points);
  SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 100.0 * 96 / targets.rows()),
                           SpringForceModel::Attach::NearestEachStep);
  SurfaceQuadrature none;
  springs.beginLevel(surface, none, points);
  double potential = 0.0;
  const MatrixX3 residual = springs.generalizedForce(points, potential) - matrices.stiffness * points;
  for (auto _ : state) {
    StaticSolver solver(surface, matrices.stiffness, {});
    benchmark::DoNotOptimize(solver.direction({&springs}, points, residual, false));
  }
  state.counters["control_vertices"] = mesh.vertexCount();
}
BENCHMARK(BM_NewtonDirection)->ArgName("level")->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

void BM_TimeToEquilibrium(benchmark::State& state) {
  const int level = static_cast<int>(state.range(0));
  const ControlMesh mesh = cubeAtLevel(level);
  const LimitSurface surface(mesh);
  const MatrixX3 targets = sphereTargets(surface, mesh.points());
  SimulationOptions options;
  options.integrator.solver = solverOf(state.range(1));
  int steps = 0;
  for (auto _ : state) {
    SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 100.0 * 96 / targets.rows()),
                             SpringForceModel::Attach::NearestAtLevelStart);
    // The mesh is already refined: its elements are 2^-level of the initial model's.
    const SimulationResult result = simulate(mesh, {&springs}, {}, options);
    steps = result.steps;
  }
  state.counters["control_vertices"] = mesh.vertexCount();
  state.counters["steps"] = steps;
}

void solverArguments(benchmark::internal::Benchmark* b) {
  b->ArgNames({"level", "solver"});  // solver: 0 cholesky, 1 cg, 2 pcg
  for (int level = 0; level <= 3; ++level) {
    for (int solver = 0; solver <= 2; ++solver) b->Args({level, solver});
  }
  b->Unit(benchmark::kMillisecond);
}
BENCHMARK(BM_SolverSetup)->Apply(solverArguments);
BENCHMARK(BM_Step)->Apply(solverArguments);
BENCHMARK(BM_TimeToEquilibrium)->Apply(solverArguments)->Iterations(1);

}  // namespace
}  // namespace dynsub

BENCHMARK_MAIN();
