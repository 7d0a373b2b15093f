// Unit tests (no rendering): properties of the exact limit surface with exact
// answers, checked over meshes covering every case (TestMeshes.h).
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <thread>
#include <utility>

#include <gtest/gtest.h>

#include "PatchRules.h"
#include "TestMeshes.h"
#include "dynsub/ApplyOperator.h"
#include "dynsub/CatmullClark.h"
#include "dynsub/Error.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Topology.h"

namespace {

using dynsub::ElementPoint;
using dynsub::LimitSurface;
using dynsub::SurfacePoint;

// Parameters that reach deep special-element levels (1e-9 needs level 30,
// beyond the 24 tabulated ones) as well as ordinary ones.
const std::vector<double> kParameters = {0.0, 1e-9, 1e-6, 1e-3, 0.1, 0.25, 0.5, 0.6180339887, 0.9, 1.0};

double diagonalOf(const dynsub::MatrixX3& points) {
  return (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
}

class LimitSurfaceProperties : public ::testing::TestWithParam<dynsub::testing::NamedMesh> {};

// The uniform cubic B-spline in matrix form, written independently of the
// implementation's basis functions.
dynsub::Vector3 bicubic(const std::array<dynsub::Vector3, 16>& grid, double u, double v) {
  Eigen::Matrix4d m;
  m << -1, 3, -3, 1, 3, -6, 3, 0, -3, 0, 3, 0, 1, 4, 1, 0;
  m /= 6.0;
  const Eigen::RowVector4d bu = Eigen::RowVector4d(u * u * u, u * u, u, 1) * m;
  const Eigen::RowVector4d bv = Eigen::RowVector4d(v * v * v, v * v, v, 1) * m;
  dynsub::Vector3 s = dynsub::Vector3::Zero();
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) s += bu(i) * bv(j) * grid[i + 4 * j];
  return s;
}

TEST(LimitSurface, RegularGridReproducesTheBicubicBSpline) {
  // A 7 x 7 vertex grid with random heights; its centre face has a full
  // regular neighbourhood of interior valence-4 vertices.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> height(-1.0, 1.0);
  constexpr int n = 7;
  dynsub::MatrixX3 points(n * n, 3);
  std::vector<dynsub::Polygon> faces;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) points.row(j * n + i) << i + 0.1 * height(random), j, height(random);
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) faces.push_back({j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i});
  const dynsub::ControlMesh grid = dynsub::ControlMesh::fromPolygons(points, faces);
  const LimitSurface surface(grid);
  const int face = 2 * (n - 1) + 2;  // cell (2, 2): vertices 2..3 in each direction
  ASSERT_EQ(surface.elementType(face), dynsub::ElementType::Normal);
  std::array<dynsub::Vector3, 16> control;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) control[i + 4 * j] = points.row((j + 1) * n + (i + 1)).transpose();
  for (double u : kParameters) {
    for (double v : kParameters) {
      const dynsub::LimitSample sample = surface.evaluate(ElementPoint{face, u, v}, points);
      EXPECT_LE((sample.position - bicubic(control, u, v)).norm(), 1e-12) << u << ", " << v;
    }
  }
}

// elementCountOf isolates the topology alone; it must count the elements the
// surface is built with, at every isolation level the test meshes reach.
TEST_P(LimitSurfaceProperties, ElementCountOfCountsTheSurfacesElements) {
  const dynsub::ControlMesh& mesh = GetParam().mesh;
  const LimitSurface surface(mesh);
  EXPECT_EQ(LimitSurface::elementCountOf(mesh), surface.elementCount())
      << GetParam().name << " (isolation levels " << surface.isolationLevels() << ")";
}

TEST_P(LimitSurfaceProperties, OperatorRowsArePartitionsOfUnity) {
  const dynsub::ControlMesh& mesh = GetParam().mesh;
  const LimitSurface surface(mesh);
  std::vector<ElementPoint> points;
  for (int e = 0; e < surface.elementCount(); ++e)
    for (double u : kParameters)
      for (double v : {0.0, 1e-6, 0.3, 1.0}) points.push_back({e, u, v});
  const dynsub::LimitOperators ops = surface.operators(points);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(mesh.vertexCount());
  EXPECT_LE(((ops.J * ones).array() - 1.0).abs().maxCoeff(), 1e-12);
  // Derivatives grow like (2 lambda)^level near valence >= 5 vertices: the
  // zero-sum tolerance scales with each row's size.
  for (const dynsub::SparseMatrix* d : {&ops.Ju, &ops.Jv}) {
    const Eigen::VectorXd sums = *d * ones;
    const Eigen::VectorXd sizes = d->cwiseAbs() * ones;
    for (Eigen::Index r = 0; r < sums.size(); ++r) EXPECT_LE(std::abs(sums(r)), 1e-12 * (1.0 + sizes(r)));
  }
  // Second derivatives at parameter t from an extraordinary vertex cancel terms
  // ~2^level larger than themselves (level ~ log2(1/t)); they are checked where
  // t >= 1e-3 (level <= 10), and lose accuracy closer in (measured: row sums up
  // to 5e-5 at t = 1e-9 next to boundary extraordinary vertices).
  for (const dynsub::SparseMatrix* d : {&ops.Juu, &ops.Juv, &ops.Jvv}) {
    const Eigen::VectorXd sums = *d * ones;
    const Eigen::VectorXd sizes = d->cwiseAbs() * ones;
    for (Eigen::Index r = 0; r < sums.size(); ++r) {
      const double t = std::max({std::min(points[r].u, 1 - points[r].u), std::min(points[r].v, 1 - points[r].v)});
      if (t == 0.0 || t >= 1e-3) {
        EXPECT_LE(std::abs(sums(r)), 1e-10 * (1.0 + sizes(r)));
      }
    }
  }
  // The operators and direct evaluation agree.
  const dynsub::MatrixX3 control = mesh.points();
  const dynsub::MatrixX3 positions = ops.J * control;
  for (size_t k = 0; k < points.size(); k += 7) {
    EXPECT_LE((positions.row(k).transpose() - surface.evaluate(points[k], control).position).norm(), 1e-12);
  }
}

// The position's weights alone (positionStencil, and J built alone by
// limitOperator) are row 0 of the whole stencil to the bit, so that springs
// and their stiffness see one surface whichever they use.
TEST_P(LimitSurfaceProperties, PositionWeightsAreTheStencilsFirstRowToTheBit) {
  const LimitSurface surface(GetParam().mesh);
  std::vector<ElementPoint> points;
  for (int e = 0; e < surface.elementCount(); ++e)
    for (double u : kParameters)
      for (double v : {0.0, 1e-6, 0.3, 1.0}) points.push_back({e, u, v});
  const dynsub::SparseMatrix j = surface.limitOperator(points);
  for (size_t k = 0; k < points.size(); ++k) {
    const Eigen::RowVectorXd full = surface.stencil(points[k]).row(0);
    const Eigen::RowVectorXd position = surface.positionStencil(points[k]);
    ASSERT_EQ(position.size(), full.size());
    EXPECT_TRUE((position.array() == full.array()).all()) << "element " << points[k].element;
    const std::vector<int>& columns = surface.elementColumns(points[k].element);
    for (size_t c = 0; c < columns.size(); ++c) {
      EXPECT_EQ(j.coeff(static_cast<Eigen::Index>(k), columns[c]), full(static_cast<Eigen::Index>(c)));
    }
  }
}

TEST_P(LimitSurfaceProperties, RefinementPreservesTheLimitSurface) {
  const dynsub::ControlMesh& mesh = GetParam().mesh;
  const dynsub::SubdividedMesh refined = dynsub::subdivide(mesh);
  const LimitSurface coarse(mesh);
  const LimitSurface fine(refined.mesh);
  const dynsub::MatrixX3 coarsePoints = mesh.points();
  const dynsub::MatrixX3 finePoints = refined.mesh.points();
  const double tolerance = 1e-10 * diagonalOf(coarsePoints);
  const dynsub::Topology topology = mesh.topology();
  int parametricFace = 0;
  int childOffset = 0;
  for (int f = 0; f < topology.faceCount(); ++f) {
    const int n = topology.faceSize(f);
    for (int sub = 0; sub < (n == 4 ? 1 : n); ++sub, ++parametricFace) {
      for (double u : kParameters) {
        for (double v : kParameters) {
          // The same point on the refined mesh: child k of a quad covers
          // quadrant k (CatmullClark.h); an n-gon's sub-face is its child.
          SurfacePoint finePoint{childOffset + sub, u, v};
          if (n == 4) {
            const int k = u < 0.5 ? (v < 0.5 ? 0 : 3) : (v < 0.5 ? 1 : 2);
            const double frames[4][2] = {{u, v}, {v, 1 - u}, {1 - u, 1 - v}, {1 - v, u}};
            finePoint = {childOffset + k, std::min(1.0, 2 * frames[k][0]), std::min(1.0, 2 * frames[k][1])};
          }
          const dynsub::LimitSample a = coarse.evaluate(SurfacePoint{parametricFace, u, v}, coarsePoints);
          const dynsub::LimitSample b = fine.evaluate(finePoint, finePoints);
          EXPECT_LE((a.position - b.position).norm(), tolerance)
              << GetParam().name << " face " << parametricFace << " (" << u << ", " << v << ")";
          EXPECT_GE(a.normal.dot(b.normal), 1.0 - 1e-9)
              << GetParam().name << " face " << parametricFace << " (" << u << ", " << v << ")";
        }
      }
    }
    childOffset += n;
  }
}

TEST_P(LimitSurfaceProperties, PositionsAndNormalsAgreeAcrossSharedEdges) {
  const dynsub::ControlMesh& mesh = GetParam().mesh;
  const LimitSurface surface(mesh);
  const dynsub::Topology& base = surface.baseTopology();
  const dynsub::MatrixX3 control = mesh.points();
  const double tolerance = 1e-12 * diagonalOf(control);
  // Point at parameter t along side k of an element, from corner k to k+1.
  auto along = [](int element, int side, double t) {
    const double corners[5][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}};
    return ElementPoint{element, (1 - t) * corners[side][0] + t * corners[side + 1][0],
                        (1 - t) * corners[side][1] + t * corners[side + 1][1]};
  };
  for (int e = 0; e < base.edgeCount(); ++e) {
    if (base.isBoundaryEdge(e)) continue;
    const auto [f, g] = base.edgeFaces(e);
    int sideF = 0, sideG = 0;
    while (base.faceEdge(f, sideF) != e) ++sideF;
    while (base.faceEdge(g, sideG) != e) ++sideG;
    for (double t : {1e-7, 0.2, 0.5, 0.77, 1.0 - 1e-7}) {
      // The neighbour runs along the shared edge the other way.
      const dynsub::LimitSample a = surface.evaluate(along(f, sideF, t), control);
      const dynsub::LimitSample b = surface.evaluate(along(g, sideG, 1.0 - t), control);
      EXPECT_LE((a.position - b.position).norm(), tolerance) << GetParam().name << " edge " << e << " t " << t;
      EXPECT_GE(a.normal.dot(b.normal), 1.0 - 1e-10) << GetParam().name << " edge " << e << " t " << t;
    }
  }
}

TEST_P(LimitSurfaceProperties, ParametricFacesMapToElementsAndBack) {
  const LimitSurface surface(GetParam().mesh);
  for (int f = 0; f < surface.parametricFaceCount(); ++f) {
    for (double u : {0.0, 0.3, 0.5, 0.8}) {
      for (double v : {0.1, 0.5, 0.7, 1.0}) {
        const SurfacePoint back = surface.toSurfacePoint(surface.toElementPoint({f, u, v}));
        EXPECT_EQ(back.face, f);
        EXPECT_NEAR(back.u, u, 1e-15);
        EXPECT_NEAR(back.v, v, 1e-15);
      }
    }
  }
}

TEST_P(LimitSurfaceProperties, ControlVertexLimitsLieOnTheSurface) {
  const dynsub::ControlMesh& mesh = GetParam().mesh;
  const LimitSurface surface(mesh);
  const dynsub::MatrixX3 control = mesh.points();
  const dynsub::MatrixX3 limits = surface.controlVertexLimitOperator() * control;
  const dynsub::Topology& base = surface.baseTopology();
  // Control vertex i is base vertex i, a corner of its elements.
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const int element = base.vertexFaces(v).front();
    const int corner = base.corner(element, v);
    const double at[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const dynsub::LimitSample sample = surface.evaluate(ElementPoint{element, at[corner][0], at[corner][1]}, control);
    EXPECT_LE((limits.row(v).transpose() - sample.position).norm(), 1e-12 * diagonalOf(control));
  }
}

INSTANTIATE_TEST_SUITE_P(AllMeshes, LimitSurfaceProperties, ::testing::ValuesIn(dynsub::testing::allTestMeshes()),
                         [](const auto& info) { return info.param.name; });

INSTANTIATE_TEST_SUITE_P(Creased, LimitSurfaceProperties, ::testing::ValuesIn(dynsub::testing::creasedTestMeshes()),
                         [](const auto& info) { return info.param.name; });

// A creased surface is one surface: along every creased edge of the control
// mesh the faces on its two sides meet, and at a sharp crease their normals
// differ (the cube's faces meet at about 90 degrees).
TEST(LimitSurface, CreasedFacesMeetAlongTheirCreases) {
  for (const dynsub::testing::NamedMesh& named : dynsub::testing::creasedTestMeshes()) {
    const dynsub::ControlMesh& mesh = named.mesh;
    const dynsub::Topology& topology = mesh.topology();
    const LimitSurface surface(mesh);
    const dynsub::MatrixX3 control = mesh.points();
    const double tolerance = 1e-12 * diagonalOf(control);
    std::vector<int> offset{0};  // first parametric face of each control face
    for (int f = 0; f < topology.faceCount(); ++f) {
      offset.push_back(offset.back() + (topology.faceSize(f) == 4 ? 1 : topology.faceSize(f)));
    }
    // The point at t along side k of face f (corner k to k + 1): on a quad's
    // one parametric face; on an n-gon's sub-faces k (first half, side 0) and
    // k + 1 (second half, side 3 from its corner 3 to 0).
    auto onSide = [&](int f, int k, double t) {
      const int n = topology.faceSize(f);
      if (n != 4) {
        return t <= 0.5 ? SurfacePoint{offset[f] + k, 2 * t, 0.0}
                        : SurfacePoint{offset[f] + (k + 1) % n, 0.0, 2 - 2 * t};
      }
      const double corners[5][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}};
      return SurfacePoint{offset[f], (1 - t) * corners[k][0] + t * corners[k + 1][0],
                          (1 - t) * corners[k][1] + t * corners[k + 1][1]};
    };
    int checked = 0;
    for (int e = 0; e < topology.edgeCount(); ++e) {
      if (topology.isBoundaryEdge(e) || topology.edgeSharpness(e) == 0.0) continue;
      const auto [f, g] = topology.edgeFaces(e);
      int sideF = 0, sideG = 0;
      while (topology.faceEdge(f, sideF) != e) ++sideF;
      while (topology.faceEdge(g, sideG) != e) ++sideG;
      for (double t : {0.0, 0.3, 0.5, 0.8, 1.0}) {
        const dynsub::LimitSample a = surface.evaluate(onSide(f, sideF, t), control);
        const dynsub::LimitSample b = surface.evaluate(onSide(g, sideG, 1.0 - t), control);
        EXPECT_LE((a.position - b.position).norm(), tolerance) << named.name << " edge " << e << " t " << t;
        if (named.name == "cube8sharp" && t == 0.5) {
          EXPECT_LT(a.normal.dot(b.normal), 0.5) << "edge " << e;
        }
        ++checked;
      }
    }
    EXPECT_GT(checked, 0) << named.name;
  }
}

// Each step of semi-sharpness refines the whole surface; above 4 a mesh is
// refused when its creases are set, naming the crease.
TEST(LimitSurface, SemiSharpCreasesAboveFourAreRefused) {
  dynsub::ControlMesh cube = dynsub::makeCube98();
  const auto [a, b] = cube.topology().edgeVertices(0);
  cube.setCreases({{a, b, 4.0}});
  EXPECT_EQ(LimitSurface(cube).isolationLevels(), 4);  // four crease steps; the cube needs no isolation
  try {
    cube.setCreases({{a, b, 4.5}}, "cube");
    FAIL() << "a crease of sharpness 4.5 was accepted";
  } catch (const dynsub::Error& error) {
    const std::string message = error.what();
    // Named smaller vertex first.
    EXPECT_NE(message.find("cube: crease (" + std::to_string(std::min(a, b)) + ", " + std::to_string(std::max(a, b)) +
                           ")"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("semi-sharp creases up to 4"), std::string::npos) << message;
  }
}

// With a free basis T the surface is the mesh's own over the free points q:
// its operators are the plain surface's times T, and its points those at
// the mesh points T q, to rounding (1e-12 of the mesh's size).
TEST(LimitSurface, FreeBasisIsTheMeshsSurfaceOverTheFreePoints) {
  const dynsub::ControlMesh coarse = dynsub::makeCube98();
  const dynsub::SubdividedMesh fine = dynsub::subdivide(coarse);
  // The coarse points carried by subdivision, and three of the fine mesh's
  // edge and face points free.
  std::vector<dynsub::Triplet> entries;
  const dynsub::SparseMatrix& a = fine.subdivisionMatrix;
  for (Eigen::Index row = 0; row < a.outerSize(); ++row) {
    for (dynsub::SparseMatrix::InnerIterator it(a, row); it; ++it) entries.emplace_back(row, it.col(), it.value());
  }
  const int carried = coarse.vertexCount();
  const std::vector<int> freed = {carried + 3, carried + 40, fine.mesh.vertexCount() - 1};
  for (size_t j = 0; j < freed.size(); ++j) entries.emplace_back(freed[j], carried + static_cast<int>(j), 1.0);
  dynsub::SparseMatrix basis(fine.mesh.vertexCount(), carried + static_cast<int>(freed.size()));
  basis.setFromTriplets(entries.begin(), entries.end());

  const dynsub::LimitSurface plain(fine.mesh);
  const dynsub::LimitSurface hierarchical(fine.mesh, basis);
  ASSERT_EQ(hierarchical.controlVertexCount(), basis.cols());
  ASSERT_EQ(hierarchical.elementCount(), plain.elementCount());
  std::mt19937 random(3);
  dynsub::MatrixX3 q = dynsub::MatrixX3::Random(basis.cols(), 3) * 10.0;
  q.topRows(carried) += coarse.points();
  const dynsub::MatrixX3 p = basis * q;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<dynsub::ElementPoint> points;
  for (int e = 0; e < plain.elementCount(); e += 7) points.push_back({e, unit(random), unit(random)});
  const dynsub::LimitOperators ours = hierarchical.operators(points, 1);
  const dynsub::LimitOperators theirs = plain.operators(points, 1);
  const double size = (p.colwise().maxCoeff() - p.colwise().minCoeff()).norm();
  EXPECT_LT((dynsub::MatrixX3(ours.J * q) - theirs.J * p).cwiseAbs().maxCoeff(), 1e-12 * size);
  EXPECT_LT((dynsub::MatrixX3(ours.Ju * q) - theirs.Ju * p).cwiseAbs().maxCoeff(), 1e-12 * size);
  for (const dynsub::ElementPoint& point : points) {
    EXPECT_LT((hierarchical.evaluate(point, q).position - plain.evaluate(point, p).position).norm(), 1e-12 * size);
  }
  EXPECT_EQ(hierarchical.controlVertexLimitOperator().rows(), fine.mesh.vertexCount());
  EXPECT_THROW(dynsub::LimitSurface(coarse, basis), dynsub::Error);  // rows must be the mesh's vertices
}

TEST(LimitSurface, CubeHasThePapersElements) {
  const LimitSurface surface(dynsub::makeCube98());
  int special = 0;
  for (int e = 0; e < surface.elementCount(); ++e) special += surface.elementType(e) == dynsub::ElementType::Special;
  EXPECT_EQ(surface.isolationLevels(), 0);
  EXPECT_EQ(surface.elementCount(), 96);
  EXPECT_EQ(special, 24);  // 8 extraordinary vertices x 3 faces
}

TEST(LimitSurface, TrianglesAndPentagonsAreIsolatedByRefinement) {
  EXPECT_EQ(LimitSurface(dynsub::testing::makeTetrahedron()).isolationLevels(), 2);
  EXPECT_EQ(LimitSurface(dynsub::testing::makePrism(5)).isolationLevels(), 2);
  EXPECT_EQ(LimitSurface(dynsub::testing::makeFan(5, true)).isolationLevels(), 0);
}

TEST(LimitSurface, BadParametersAreRejected) {
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  const LimitSurface surface(cube);
  EXPECT_THROW(surface.evaluate(ElementPoint{96, 0.5, 0.5}, cube.points()), dynsub::Error);
  EXPECT_THROW(surface.evaluate(ElementPoint{0, 1.5, 0.5}, cube.points()), dynsub::Error);
  EXPECT_THROW(surface.evaluate(ElementPoint{0, std::nan(""), 0.5}, cube.points()), dynsub::Error);
  EXPECT_THROW(surface.evaluate(SurfacePoint{-1, 0.5, 0.5}, cube.points()), dynsub::Error);
  EXPECT_THROW(surface.evaluate(ElementPoint{0, 0.5, 0.5}, cube.points().topRows(10)), dynsub::Error);
}

TEST(LimitSurface, EqualNeighbourhoodsShareOneLocalTopology) {
  // The cube's rotations take any (corner, face at it) pair to any other, so
  // the 24 neighbourhoods of cube98's special elements are one and the same;
  // numbered by structure, not by the mesh's numbering, they must be equal
  // however the mesh is numbered (here: vertices and faces shuffled). This is
  // what lets LimitSurface build one subdivision step for all 24.
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  std::mt19937 random(3);
  std::vector<int> renumber(cube.vertexCount());
  std::iota(renumber.begin(), renumber.end(), 0);
  std::shuffle(renumber.begin(), renumber.end(), random);
  dynsub::MatrixX3 points(cube.vertexCount(), 3);
  for (int v = 0; v < cube.vertexCount(); ++v) points.row(renumber[v]) = cube.points().row(v);
  std::vector<dynsub::Polygon> faces = cube.faces();
  for (dynsub::Polygon& face : faces) {
    for (int& v : face) v = renumber[v];
  }
  std::shuffle(faces.begin(), faces.end(), random);
  const dynsub::Topology topology(cube.vertexCount(), faces);

  std::vector<std::vector<dynsub::Polygon>> neighbourhoods;
  for (int x = 0; x < topology.vertexCount(); ++x) {
    if (topology.isRegularVertex(x)) continue;
    for (int f : topology.vertexFaces(x))
      neighbourhoods.push_back(dynsub::detail::extractNeighbourhood(topology, x, f).faces);
  }
  ASSERT_EQ(neighbourhoods.size(), 24u);
  for (const std::vector<dynsub::Polygon>& neighbourhood : neighbourhoods) {
    EXPECT_EQ(neighbourhood, neighbourhoods.front());
  }
}

TEST(LimitSurface, ManyThreadsEvaluatingAtOnceAgreeWithOne) {
  // Special elements tabulate their levels when a point first needs them,
  // from whichever thread asks. Points at every depth (kParameters reach
  // level 30) on every element, evaluated by 4 threads at once on a fresh
  // surface, each in its own order, must equal one thread's results exactly.
  for (const dynsub::ControlMesh& mesh : {dynsub::makeCube98(), dynsub::testing::makeFan(5, true), dynsub::testing::makeFan(5, false),
                                          dynsub::testing::makeTetrahedron()}) {
    std::vector<ElementPoint> points;
    const LimitSurface one(mesh);
    for (int e = 0; e < one.elementCount(); ++e) {
      if (one.elementType(e) != dynsub::ElementType::Special) continue;
      for (double u : kParameters)
        for (double v : kParameters) points.push_back({e, u, v});
    }
    ASSERT_FALSE(points.empty());
    std::vector<dynsub::LimitSample> expected;
    for (const ElementPoint& point : points) expected.push_back(one.evaluate(point, mesh.points()));

    const LimitSurface many(mesh);
    constexpr int kThreads = 4;
    std::vector<std::vector<dynsub::LimitSample>> results(kThreads, std::vector<dynsub::LimitSample>(points.size()));
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
      threads.emplace_back([&, t] {
        // Thread t starts at its own quarter and walks backwards on odd t.
        for (size_t k = 0; k < points.size(); ++k) {
          const size_t start = t * points.size() / kThreads;
          const size_t i = (t % 2 ? points.size() - 1 - (start + k) % points.size() : (start + k) % points.size());
          results[t][i] = many.evaluate(points[i], mesh.points());
        }
      });
    }
    for (std::thread& thread : threads) thread.join();
    for (int t = 0; t < kThreads; ++t) {
      for (size_t i = 0; i < points.size(); ++i) {
        ASSERT_EQ(results[t][i].position, expected[i].position) << "thread " << t << ", point " << i;
        ASSERT_EQ(results[t][i].du, expected[i].du) << "thread " << t << ", point " << i;
        ASSERT_EQ(results[t][i].dvv, expected[i].dvv) << "thread " << t << ", point " << i;
      }
    }
  }
}

}  // namespace

// A special element's pieces are its structure's pieces times its map
// (LimitSurface::sharedPieces), at tabulated levels and past them, on meshes
// that need isolation (the pyramid's apex of valence 4 beside corners of
// valence 3; the L shape's boundary corners; the prism's n-gons) and one that
// does not (cube98). Few structures serve every element: the physical
// matrices integrate each once (small meshes like the L shape have as many
// structures as special elements).
TEST(LimitSurface, SpecialElementsAreTheirStructuresPiecesMapped) {
  const std::vector<std::pair<std::string, dynsub::ControlMesh>> meshes = {
      {"cube98", dynsub::makeCube98()},
      {"pyramid", dynsub::testing::makePyramid()},
      {"lshape", dynsub::testing::makeLShape()},
      {"prism5", dynsub::testing::makePrism(5)}};
  for (const auto& [name, mesh] : meshes) {
    const LimitSurface surface(mesh);
    std::vector<int> keys;
    int specials = 0;
    for (int e = 0; e < surface.elementCount(); ++e) {
      if (surface.elementType(e) != dynsub::ElementType::Special) continue;
      ++specials;
      for (const int levels : {6, 30}) {
        const dynsub::ElementPieces own = surface.elementPieces(e, levels);
        const dynsub::SharedPieces shared = surface.sharedPieces(e, levels);
        ASSERT_EQ(shared.pieces->pieces.size(), own.pieces.size()) << name;
        ASSERT_EQ(shared.map.cols(), static_cast<Eigen::Index>(own.columns.size())) << name;
        for (size_t k = 0; k < own.pieces.size(); ++k) {
          const dynsub::BsplinePiece& piece = shared.pieces->pieces[k];
          const Eigen::MatrixXd grid = piece.grid * shared.map;
          const Eigen::RowVectorXd offset = piece.offset * shared.map;
          // The same sums in another order: rounding of the entries' size
          // (they shrink like the subdominant eigenvalue^level), plus that of
          // the level-0 weights (<= 1), whose row sums' rounding subdivision
          // keeps at every level as a translation (measured 2e-18).
          const double scale = own.pieces[k].grid.cwiseAbs().maxCoeff();
          EXPECT_LT((grid - own.pieces[k].grid).cwiseAbs().maxCoeff(), 1e-12 * scale + 1e-16)
              << name << " " << e << " " << k;
          EXPECT_LT((offset - own.pieces[k].offset).cwiseAbs().maxCoeff(), 1e-14) << name << " " << e;
          EXPECT_EQ(piece.swapped, own.pieces[k].swapped);
          EXPECT_EQ(piece.size, own.pieces[k].size);
        }
        keys.push_back(shared.key);
      }
    }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    ASSERT_GT(specials, 0) << name;
    // Per (structure, corner, levels): cube98's 24 special elements are one
    // structure in 4 corners, so 8 keys for the two level counts.
    if (name == "cube98") {
      EXPECT_LE(keys.size(), 8u);
    }
  }
}

// SurfaceState's grids are patchOperator() times the control points to the
// bit, whether it computes them from the elements (before the operator is
// asked for) or by the operator (after): the same sums in the same order.
TEST(SurfaceState, GridsAreThePatchOperatorsProductBeforeAndAfterItIsBuilt) {
  for (const auto& [name, mesh] : {std::pair<std::string, dynsub::ControlMesh>{"cube98", dynsub::makeCube98()},
                                   {"pyramid", dynsub::testing::makePyramid()}}) {
    const LimitSurface surface(mesh);
    dynsub::SurfaceState state(surface);
    dynsub::MatrixX3 controlPoints = mesh.points();
    controlPoints.col(1).array() += 0.1 * controlPoints.col(0).array().square();
    state.reset(controlPoints);
    const dynsub::MatrixX3 fromElements = state.grids();
    const dynsub::MatrixX3 expected = dynsub::applyOperator(surface.patchOperator(), controlPoints);
    ASSERT_EQ(fromElements.rows(), 16 * surface.elementCount()) << name;
    EXPECT_TRUE((fromElements.array() == expected.array()).all()) << name;
    EXPECT_EQ(state.patchOperator().nonZeros(), surface.patchOperator().nonZeros()) << name;
    state.reset(controlPoints);
    EXPECT_TRUE((state.grids().array() == expected.array()).all()) << name;
  }
}

// SurfaceState keeps each special element's subpatch grid points for one
// state; its evaluations must be LimitSurface::evaluate's to rounding, at
// every depth (cached levels and past them) and after a reset to another
// state, and from several threads at once.
TEST(SurfaceState, EvaluatesAsTheSurfaceDoesAtEveryDepthAndState) {
  const dynsub::ControlMesh mesh = dynsub::testing::makePyramid();
  const LimitSurface surface(mesh);
  dynsub::SurfaceState state(surface);
  std::vector<ElementPoint> points;
  for (int e = 0; e < surface.elementCount(); ++e) {
    for (const double t : {0.0, 0.3, 0.7, 1.0}) points.push_back(ElementPoint{e, t, 1.0 - t});
    for (int depth = 1; depth <= 20; depth += 3) {
      const double d = std::ldexp(0.7, -depth);
      for (const double u : {d, 1.0 - d}) {
        for (const double v : {0.5 * d, 1.0 - 0.5 * d}) points.push_back(ElementPoint{e, u, v});
      }
    }
  }
  dynsub::MatrixX3 controlPoints = mesh.points();
  for (int round = 0; round < 2; ++round) {
    state.reset(controlPoints);
    std::vector<dynsub::LimitSample> fromThreads(points.size());
    std::vector<std::thread> threads;
    for (int t = 0; t < 3; ++t) {
      threads.emplace_back([&, t] {
        for (size_t i = t; i < points.size(); i += 3) fromThreads[i] = state.evaluate(points[i]);
      });
    }
    for (std::thread& t : threads) t.join();
    for (size_t i = 0; i < points.size(); ++i) {
      const dynsub::LimitSample expected = surface.evaluate(points[i], controlPoints);
      const dynsub::LimitSample& actual = fromThreads[i];
      // The same products summed in another order; derivatives grow 2^level
      // near the vertex, hence tolerances relative to each quantity's size.
      auto near = [](const dynsub::Vector3& a, const dynsub::Vector3& b) {
        return (a - b).norm() <= 1e-12 * std::max(1.0, b.norm());
      };
      EXPECT_TRUE(near(actual.position, expected.position)) << round << " " << i;
      EXPECT_TRUE(near(actual.du, expected.du)) << round << " " << i;
      EXPECT_TRUE(near(actual.dv, expected.dv)) << round << " " << i;
      EXPECT_TRUE(near(actual.duu, expected.duu)) << round << " " << i;
      EXPECT_TRUE(near(actual.dvv, expected.dvv)) << round << " " << i;
    }
    controlPoints = (controlPoints * 1.3).eval();
    controlPoints.col(0).array() += 2.0;
  }
}
