// Subdivision solids: Table 1's counts of McDonnell and Qin, tri-cubic
// B-spline reproduction on a regular lattice, the matrix A, lattice files and
// the errors for invalid lattices. No rendering.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "dynsub/Error.h"
#include "dynsub/LatticeIO.h"
#include "dynsub/SolidSubdivision.h"

namespace dynsub {
namespace {

struct Counts {
  int points, edges, faces, cells;
};

Counts countsOf(const Lattice& l) { return {l.pointCount(), l.edgeCount(), l.faceCount(), l.cellCount()}; }

void expectCounts(const Lattice& l, const Counts& expected, const std::string& what) {
  const Counts c = countsOf(l);
  EXPECT_EQ(c.points, expected.points) << what;
  EXPECT_EQ(c.edges, expected.edges) << what;
  EXPECT_EQ(c.faces, expected.faces) << what;
  EXPECT_EQ(c.cells, expected.cells) << what;
}

// Table 1: initial counts and the counts after the given levels.
TEST(SolidSubdivision, ReproducesTable1Counts) {
  const Lattice cube3 = regularLattice(2, 2, 2);
  expectCounts(cube3, {27, 54, 36, 8}, "Cube (3^3)");
  expectCounts(subdivideSolid(cube3, 2).lattice, {729, 1944, 1728, 512}, "Cube (3^3), level 2");
  expectCounts(subdivideSolid(cube3, 3).lattice, {4913, 13872, 13056, 4096}, "Cube (3^3), level 3");
  const Lattice cube4 = regularLattice(3, 3, 3);
  expectCounts(cube4, {64, 144, 108, 27}, "Cube (4^3)");
  expectCounts(subdivideSolid(cube4, 1).lattice, {343, 882, 756, 216}, "Cube (4^3), level 1");
  expectCounts(subdivideSolid(cube4, 2).lattice, {2197, 6084, 5616, 1728}, "Cube (4^3), level 2");
  // Cube w/ holes: the 3 x 3 x 3 cube without its centre and face-centre cells.
  const Lattice holes = regularLattice(3, 3, 3, 1.0, {13, 4, 22, 10, 16, 12, 14});
  expectCounts(holes, {64, 144, 96, 20}, "Cube w/ holes");
  expectCounts(subdivideSolid(holes, 2).lattice, {1900, 5040, 4416, 1280}, "Cube w/ holes, level 2");
}

// refinedCounts agrees with the lattices subdivideSolid builds, on the cubes
// and on cells other than hexahedra: a pyramid (a corner of 4 edges) and a
// tetrahedron.
TEST(SolidSubdivision, CountsFromIncidencesAgreeWithTheRefinedLattices) {
  MatrixX3 pyramidPoints(5, 3);
  pyramidPoints << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 1;
  MatrixX3 tetrahedronPoints(4, 3);
  tetrahedronPoints << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  const std::vector<std::pair<std::string, Lattice>> lattices = {
      {"cube3", regularLattice(2, 2, 2)},
      {"holes", regularLattice(3, 3, 3, 1.0, {13, 4, 22, 10, 16, 12, 14})},
      {"pyramid", Lattice::fromCells(pyramidPoints, {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}},
                                     {{0, 1, 2, 3, 4}})},
      {"tetrahedron",
       Lattice::fromCells(tetrahedronPoints, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}}, {{0, 1, 2, 3}})}};
  for (const auto& [name, lattice] : lattices) {
    for (int level = 0; level <= 3; ++level) {
      const Counts built = countsOf(subdivideSolid(lattice, level).lattice);
      const LatticeCounts counted = refinedCounts(lattice, level);
      const std::string what = name + ", level " + std::to_string(level);
      EXPECT_EQ(counted.points, static_cast<std::uint64_t>(built.points)) << what;
      EXPECT_EQ(counted.edges, static_cast<std::uint64_t>(built.edges)) << what;
      EXPECT_EQ(counted.faces, static_cast<std::uint64_t>(built.faces)) << what;
      EXPECT_EQ(counted.cells, static_cast<std::uint64_t>(built.cells)) << what;
    }
  }
}

// The uniform tri-cubic B-spline's refinement along one axis: a fine point at
// even index 2i is (p[i-1] + 6 p[i] + p[i+1]) / 8, at odd index 2i + 1 it is
// (p[i] + p[i+1]) / 2.
std::vector<std::pair<int, double>> bsplineMask(int fine) {
  if (fine % 2 == 0) return {{fine / 2 - 1, 1.0 / 8}, {fine / 2, 6.0 / 8}, {fine / 2 + 1, 1.0 / 8}};
  return {{fine / 2, 0.5}, {fine / 2 + 1, 0.5}};
}

TEST(SolidSubdivision, RegularInteriorIsTheTriCubicBSplineSolid) {
  const int cells = 6, n = cells + 1;
  Lattice lattice = regularLattice(cells, cells, cells);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  MatrixX3 points = lattice.points();
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    for (int a = 0; a < 3; ++a) points(i, a) += jitter(random);
  lattice.setPoints(points);
  auto grid = [&](int p) { return Eigen::Vector3i(p % n, (p / n) % n, p / (n * n)); };

  const SolidRefinement refined = subdivideSolid(lattice);
  // Each refined point comes from an element; its fine-grid index is twice the
  // average grid index of the element's points.
  std::vector<std::vector<int>> sources;
  for (int p = 0; p < lattice.pointCount(); ++p) sources.push_back({p});
  for (const auto& e : lattice.edges()) sources.push_back({e[0], e[1]});
  for (const auto& f : lattice.faces()) sources.push_back(f);
  for (const auto& c : lattice.cellPoints()) sources.push_back(c);
  ASSERT_EQ(static_cast<int>(sources.size()), refined.lattice.pointCount());

  int compared = 0;
  for (std::size_t r = 0; r < sources.size(); ++r) {
    Eigen::Vector3i sum = Eigen::Vector3i::Zero();
    for (int p : sources[r]) sum += grid(p);
    const Eigen::Vector3i fine = 2 * sum / static_cast<int>(sources[r].size());
    // Only points whose B-spline stencil lies inside the lattice (the
    // boundary follows the surface rules instead).
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && fine[a] >= 2 && fine[a] <= 2 * (n - 1) - 2;
    if (!inside) continue;
    Vector3 expected = Vector3::Zero();
    for (const auto& [i, wi] : bsplineMask(fine[0]))
      for (const auto& [j, wj] : bsplineMask(fine[1]))
        for (const auto& [k, wk] : bsplineMask(fine[2]))
          expected += wi * wj * wk * points.row(i + n * (j + n * k)).transpose();
    EXPECT_LT((refined.lattice.points().row(r).transpose() - expected).norm(), 1e-12) << "refined point " << r;
    ++compared;
  }
  EXPECT_EQ(compared, 9 * 9 * 9);  // fine indices 2..10 on each axis of the 13-point fine grid
}

TEST(SolidSubdivision, EveryRefinedPointIsAnAffineBlendAndLevelsCompose) {
  const Lattice holes = regularLattice(3, 3, 3, 2.0, {13, 4, 22, 10, 16, 12, 14});
  const SolidRefinement two = subdivideSolid(holes, 2);
  const Eigen::VectorXd rowSums = two.A * Eigen::VectorXd::Ones(holes.pointCount());
  EXPECT_LT((rowSums - Eigen::VectorXd::Ones(rowSums.size())).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((two.A * holes.points() - two.lattice.points()).cwiseAbs().maxCoeff(), 1e-12);
  // Translating the lattice translates the solid.
  Lattice moved = holes;
  MatrixX3 shifted = holes.points();
  shifted.rowwise() += Eigen::RowVector3d(3, -1, 2);
  moved.setPoints(shifted);
  MatrixX3 expected = two.lattice.points();
  expected.rowwise() += Eigen::RowVector3d(3, -1, 2);
  EXPECT_LT((subdivideSolid(moved, 2).lattice.points() - expected).cwiseAbs().maxCoeff(), 1e-12);
  // The refined lattice stays valid: each cell closed, each face in 1 or 2 cells.
  for (const auto& cells : two.lattice.faceCells()) EXPECT_TRUE(cells.size() == 1 || cells.size() == 2);
}

TEST(SolidSubdivision, TheBoundarySurfaceShrinksTowardsItsLimitButStaysInsideTheHull) {
  // A cube's boundary follows Catmull-Clark surface rules: the corners pull
  // in, the face centres stay on the faces.
  const Lattice cube = regularLattice(1, 1, 1, 2.0);
  const Lattice fine = subdivideSolid(cube, 3).lattice;
  const Eigen::RowVector3d low = fine.points().colwise().minCoeff(), high = fine.points().colwise().maxCoeff();
  for (int a = 0; a < 3; ++a) {
    EXPECT_GT(low(a), 0.0);
    EXPECT_LT(high(a), 2.0);
  }
}

TEST(SculptingTopology, ExtrudeAddsACellOnABoundaryFaceAndDeleteRemovesOne) {
  const Lattice cube3 = regularLattice(2, 2, 2);
  // Face 0 of cell 0 is its bottom (z = 0): a boundary face.
  ASSERT_TRUE(cube3.isBoundaryFace(0));
  const Lattice grown = extrudeFace(cube3, 0);
  expectCounts(grown, {31, 62, 41, 9}, "Cube (3^3) with a face extruded");
  EXPECT_FALSE(grown.isBoundaryFace(0));
  // The new points lie one cell below, outside the cube.
  for (int p = 27; p < 31; ++p) EXPECT_DOUBLE_EQ(grown.points()(p, 2), -1.0);
  EXPECT_EQ(grown.points().topRows(27), cube3.points());
  // The new boundary faces face outward, as the cube's own do: each loop's
  // normal points away from the new cell's centre.
  const Vector3 cellCentre(0.5, 0.5, -0.5);
  for (int f = cube3.faceCount(); f < grown.faceCount(); ++f) {
    const auto& loop = grown.faces()[f];
    Vector3 normal = Vector3::Zero(), centre = Vector3::Zero();
    for (std::size_t i = 0; i < loop.size(); ++i) {
      normal += Vector3(grown.points().row(loop[i]).transpose()).cross(grown.points().row(loop[(i + 1) % loop.size()]).transpose());
      centre += grown.points().row(loop[i]).transpose() / loop.size();
    }
    EXPECT_GT(normal.dot(centre - cellCentre), 0.0) << "new face " << f << " faces inward";
  }
  expectCounts(subdivideSolid(grown).lattice, {31 + 62 + 41 + 9, 2 * 62 + 4 * 41 + 6 * 9, 4 * 41 + 12 * 9, 8 * 9},
               "extruded, level 1");
  // Deleting the corner cell 0: its corner point, 3 edges and 3 boundary faces go.
  std::vector<int> kept;
  const Lattice trimmed = deleteCell(cube3, 0, &kept);
  expectCounts(trimmed, {26, 51, 33, 7}, "Cube (3^3) without a corner cell");
  EXPECT_EQ(kept[0], -1);
  EXPECT_EQ(kept[1], 0);
  // Deleting the extruded cell gives the cube back.
  expectCounts(deleteCell(grown, 8), countsOf(cube3), "extruded, then deleted");
  EXPECT_THROW(extrudeFace(cube3, cube3.faceCount()), Error);
  int interior = 0;
  while (cube3.isBoundaryFace(interior)) ++interior;
  EXPECT_THROW(extrudeFace(cube3, interior), Error);
  EXPECT_THROW(deleteCell(regularLattice(1, 1, 1), 0), Error);
}

// --- files and errors ---------------------------------------------------------

class LatticeFiles : public ::testing::Test {
 protected:
  std::string file(const std::string& name, const std::string& text) {
    const std::string path = (std::filesystem::temp_directory_path() / ("dynsub_solids_" + name)).string();
    std::ofstream(path) << text;
    paths_.push_back(path);
    return path;
  }
  void TearDown() override {
    for (const auto& p : paths_) std::filesystem::remove(p);
  }
  static std::string message(const std::string& path) {
    try {
      readLattice(path);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
  std::vector<std::string> paths_;
};

// A unit tetrahedron as one cell.
const char* const kTetrahedron =
    "dynsub-lattice 1\npoints 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    "faces 4\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n"
    "cells 1\n4 0 1 2 3\n";

TEST_F(LatticeFiles, RoundTrip) {
  const Lattice cube4 = regularLattice(3, 3, 3, 1.5);
  const std::string path = (std::filesystem::temp_directory_path() / "dynsub_solids_roundtrip.lattice").string();
  paths_.push_back(path);
  writeLattice(cube4, path);
  const Lattice back = readLattice(path);
  EXPECT_EQ(back.faces(), cube4.faces());
  EXPECT_EQ(back.cells(), cube4.cells());
  EXPECT_EQ(back.points(), cube4.points());
  const Lattice tetrahedron = readLattice(file("tet.lattice", kTetrahedron));
  expectCounts(tetrahedron, {4, 6, 4, 1}, "tetrahedron");
  // One cell of 4 corners gives 4 hexahedra.
  expectCounts(subdivideSolid(tetrahedron).lattice, {15, 28, 18, 4}, "tetrahedron, level 1");
  const std::string vtu = (std::filesystem::temp_directory_path() / "dynsub_solids.vtu").string();
  paths_.push_back(vtu);
  writeLattice(cube4, vtu);
  // VTK reads every cell back as a polyhedron with the lattice's faces, and
  // each cell's count of boundary faces.
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(vtu.c_str());
  reader->Update();
  ASSERT_EQ(reader->GetErrorCode(), 0);
  vtkUnstructuredGrid* grid = reader->GetOutput();
  ASSERT_EQ(grid->GetNumberOfPoints(), cube4.pointCount());
  ASSERT_EQ(grid->GetNumberOfCells(), cube4.cellCount());
  for (int i = 0; i < cube4.pointCount(); ++i) {
    double p[3];
    grid->GetPoint(i, p);
    for (int a = 0; a < 3; ++a) ASSERT_EQ(p[a], cube4.points()(i, a));
  }
  vtkDataArray* boundary = grid->GetCellData()->GetArray("BoundaryFaces");
  ASSERT_NE(boundary, nullptr);
  vtkNew<vtkIdList> stream;
  for (int c = 0; c < cube4.cellCount(); ++c) {
    ASSERT_EQ(grid->GetCellType(c), VTK_POLYHEDRON);
    grid->GetFaceStream(c, stream);
    std::vector<int> expected{static_cast<int>(cube4.cells()[c].size())};
    int boundaryFaces = 0;
    for (int f : cube4.cells()[c]) {
      boundaryFaces += cube4.isBoundaryFace(f);
      expected.push_back(static_cast<int>(cube4.faces()[f].size()));
      expected.insert(expected.end(), cube4.faces()[f].begin(), cube4.faces()[f].end());
    }
    ASSERT_EQ(stream->GetNumberOfIds(), static_cast<vtkIdType>(expected.size()));
    for (size_t k = 0; k < expected.size(); ++k) ASSERT_EQ(stream->GetId(static_cast<vtkIdType>(k)), expected[k]);
    EXPECT_EQ(boundary->GetTuple1(c), boundaryFaces);
  }
}

TEST_F(LatticeFiles, InvalidLatticesAreNamed) {
  EXPECT_NE(message(file("missing.lattice", "")).find("ends early"), std::string::npos);
  EXPECT_NE(message("/nonexistent/x.lattice").find("no such file"), std::string::npos);
  EXPECT_NE(message(file("header.lattice", "lattice 2\n")).find("line 1"), std::string::npos);
  std::string text = kTetrahedron;
  EXPECT_NE(message(file("range.lattice", std::string(text).replace(text.find("3 0 2 1"), 7, "3 0 2 9")))
                .find("face 0 uses point 9"),
            std::string::npos);
  // A fifth face nobody uses, on a fifth point: dangling.
  std::string dangling = std::string(text).replace(text.find("faces 4"), 7, "faces 5");
  dangling.replace(dangling.find("points 4"), 8, "points 5");
  dangling.replace(dangling.find("0 0 1\n"), 6, "0 0 1\n1 1 1\n");
  dangling.replace(dangling.find("cells 1"), 7, "3 1 2 4\ncells 1");
  EXPECT_NE(message(file("dangling.lattice", dangling)).find("dangles"), std::string::npos);
  // A cell missing a face is open.
  std::string open = std::string(text).replace(text.find("4 0 1 2 3"), 9, "3 0 1 2");
  EXPECT_NE(message(file("open.lattice", open)).find("fewer than 4 faces"), std::string::npos);
  // A cell past the announced count would be dropped unseen.
  EXPECT_NE(message(file("extra.lattice", text + "4 0 1 2 3\n")).find("line 14: more data after the 1 cells"),
            std::string::npos);
  EXPECT_THROW(Lattice::fromCells(regularLattice(1, 1, 1).points(),
                                  {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}},
                                  {{0, 1, 2, 3, 4}}),
               Error);  // five faces of a hexahedron: not closed
  try {
    Lattice::fromCells(regularLattice(1, 1, 1).points(),
                       {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}},
                       {{0, 1, 2, 3, 4}}, "box.lattice");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("box.lattice: cell 0 is not closed"), std::string::npos) << e.what();
  }
  EXPECT_NE(message(file("truncated.lattice", "dynsub-lattice 1\npoints 4\n0 0 0\n1 0 0\n")).find("ends early"),
            std::string::npos);
  EXPECT_NE(message(file("nan.lattice", std::string(text).replace(text.find("1 0 0"), 5, "nan 0 0"))).find("line 4"),
            std::string::npos);
  EXPECT_THROW(readLattice(file("cube.obj", "v 0 0 0\n")), Error);
  // Every point at one place, and a face whose corners lie on a line: faces
  // of no area.
  std::string same = std::string(text).replace(text.find("1 0 0\n0 1 0\n0 0 1"), 17, "0 0 0\n0 0 0\n0 0 0");
  EXPECT_NE(message(file("same.lattice", same)).find("face 0 is degenerate: its area is zero"), std::string::npos);
  std::string line = std::string(text).replace(text.find("0 1 0\n0 0 1"), 5, "2 0 0");
  EXPECT_NE(message(file("line.lattice", line)).find("face 0 is degenerate"), std::string::npos);
  // A mistyped coordinate far from the rest: the faces have an area, which
  // is none beside the lattice's extent.
  std::string far = std::string(text).replace(text.find("1 0 0"), 5, "1e6 0 0");
  EXPECT_NE(message(file("far.lattice", far)).find("is a point far from the others"), std::string::npos)
      << message(file("far.lattice", far));
}

// A number is read whole: a decimal comma or a stray character is refused,
// not read as the number before it. A cell is one closed shell, a face two
// cells share is listed once, and two cells are not the same faces: each
// would otherwise be subdivided as something else (two tetrahedra bridged
// across the gap between them, a solid cut along a doubled face).
TEST_F(LatticeFiles, MistypedNumbersAndMislistedShellsAreRefused) {
  const std::string text = kTetrahedron;
  const auto replaced = [&](const std::string& from, const std::string& to) {
    return std::string(text).replace(text.find(from), from.size(), to);
  };
  EXPECT_NE(message(file("comma.lattice", replaced("0 0 1\n", "0 0 0,5\n")))
                .find("line 6: '0,5' is not a number (a point is \"x y z\", with a decimal point)"),
            std::string::npos);
  EXPECT_NE(message(file("dots.lattice", replaced("0 1 0\n", "0 1.5.5\n"))).find("line 5: expected a point"),
            std::string::npos);
  EXPECT_NE(message(file("four.lattice", replaced("0 1 0\n", "0 1 0 5\n"))).find("got 4 values"), std::string::npos);
  EXPECT_NE(message(file("count.lattice", replaced("points 4", "points 4abc"))).find("line 2: expected \"points N\""),
            std::string::npos);

  const std::string two =
      "dynsub-lattice 1\npoints 8\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 0\n4 0 0\n3 1 0\n3 0 1\n"
      "faces 8\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n3 4 6 5\n3 4 5 7\n3 5 6 7\n3 4 7 6\n";
  EXPECT_NO_THROW(readLattice(file("two.lattice", two + "cells 2\n4 0 1 2 3\n4 4 5 6 7\n")));
  EXPECT_NE(message(file("bridged.lattice", two + "cells 1\n8 0 1 2 3 4 5 6 7\n"))
                .find("cell 0 is two or more separate shells"),
            std::string::npos);
  // A second tetrahedron on the first's face 1 2 3, which it lists again.
  const std::string glued =
      "dynsub-lattice 1\npoints 5\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n"
      "faces 8\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n3 1 3 2\n3 1 4 3\n3 2 3 4\n3 1 2 4\n"
      "cells 2\n4 0 1 2 3\n4 4 5 6 7\n";
  EXPECT_NE(message(file("glued.lattice", glued)).find("face 4 has the points of face 2"), std::string::npos);
  EXPECT_NE(message(file("twice.lattice", replaced("cells 1\n4 0 1 2 3\n", "cells 2\n4 0 1 2 3\n4 3 2 1 0\n")))
                .find("cell 1 has the faces of cell 0"),
            std::string::npos);
}

// A cell must enclose a volume, though each of its faces has an area: a
// hexahedron whose top is its bottom moved sideways within their plane is
// refused, and so is a closed shell with no inside (the real projective
// plane's six-point triangulation). The upright cube is a unit of volume.
TEST(Lattice, RefusesCellsWithNoVolume) {
  const std::vector<std::vector<int>> hexahedron = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                                    {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  MatrixX3 points = regularLattice(1, 1, 1).points();
  EXPECT_NO_THROW(Lattice::fromCells(points, hexahedron, {{0, 1, 2, 3, 4, 5}}, "cube.lattice"));
  for (int p = 4; p < 8; ++p) points.row(p) = points.row(p - 4) + Eigen::RowVector3d(0.5, 0.5, 0);
  std::string flat = "(accepted)";
  try {
    Lattice::fromCells(points, hexahedron, {{0, 1, 2, 3, 4, 5}}, "flat.lattice");
  } catch (const Error& e) {
    flat = e.what();
  }
  EXPECT_NE(flat.find("flat.lattice: cell 0 is flat: it encloses no volume"), std::string::npos) << flat;

  MatrixX3 six(6, 3);
  six << 0, 0, 0, 1, 0, 0.2, 0.3, 1, 0.1, -0.7, 0.6, 0.4, -0.6, -0.8, 0.3, 0.4, -0.9, 1.1;
  const std::vector<std::vector<int>> plane = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 1},
                                               {1, 2, 4}, {2, 3, 5}, {3, 4, 1}, {4, 5, 2}, {5, 1, 3}};
  std::string noInside = "(accepted)";
  try {
    Lattice::fromCells(six, plane, {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}}, "plane.lattice");
  } catch (const Error& e) {
    noInside = e.what();
  }
  EXPECT_NE(noInside.find("plane.lattice: cell 0's faces cannot be oriented alike"), std::string::npos) << noInside;
}

}  // namespace
}  // namespace dynsub
