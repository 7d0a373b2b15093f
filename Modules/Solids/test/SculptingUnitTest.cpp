// Sculpting (Sculpting.h, SculptScript.h): every tool acts on the running
// solid as documented, topology changes keep the rest shape and the fixed
// points, and scripts run each tool or fail naming the file and line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "dynsub/Error.h"
#include "dynsub/SculptScript.h"
#include "dynsub/Sculpting.h"

namespace dynsub {
namespace {

// Control points of `lattice` with z == 0: the base a sculptor holds.
std::vector<int> base(const Lattice& lattice) {
  std::vector<int> points;
  for (int i = 0; i < lattice.pointCount(); ++i)
    if (lattice.points()(i, 2) == 0.0) points.push_back(i);
  return points;
}

// Holds the solid by its base and pulls its top corner (2, 2, 2) by the rope
// towards `target` for `steps` steps.
void holdAndPull(Sculpture& s, const Vector3& target, int steps) {
  s.fix(base(s.rest()));
  s.grab(Vector3(2, 2, 2));
  s.pullTo(target);
  s.run(steps);
}

double largestMove(const MatrixX3& a, const MatrixX3& b) { return (a - b).rowwise().norm().maxCoeff(); }

// 80 s of motion: the default material brings the held cube back to within
// 1e-7 mm of rest, and the taller extruded one (slower) within 1e-4 mm
// (measured); the tests allow 1e-3 mm, 0.1 % of a cell.
void settle(Sculpture& s) { s.run(8000); }
constexpr double kSettled = 1e-3;  // mm

TEST(SolidRefinement, RefinedFacesAndCellsKnowTheControlElementTheyLieIn) {
  const Lattice cube3 = regularLattice(2, 2, 2);
  const SolidRefinement r = subdivideSolid(cube3, 2);
  ASSERT_EQ(r.faceOrigin.size(), static_cast<std::size_t>(r.lattice.faceCount()));
  ASSERT_EQ(r.cellOrigin.size(), static_cast<std::size_t>(r.lattice.cellCount()));
  // Every boundary face of the refined lattice lies in a boundary face of the
  // control lattice, 16 of them in each (4 x 4 at level 2), on its square.
  std::vector<int> perFace(cube3.faceCount(), 0);
  for (int f = 0; f < r.lattice.faceCount(); ++f) {
    if (!r.lattice.isBoundaryFace(f)) continue;
    const int origin = r.faceOrigin[f];
    ASSERT_GE(origin, 0);
    ASSERT_TRUE(cube3.isBoundaryFace(origin));
    ++perFace[origin];
    Vector3 low = Vector3::Constant(1e9), high = Vector3::Constant(-1e9);
    for (int p : cube3.faces()[origin]) {
      low = low.cwiseMin(cube3.points().row(p).transpose());
      high = high.cwiseMax(cube3.points().row(p).transpose());
    }
    Vector3 centre = Vector3::Zero();
    for (int p : r.lattice.faces()[f]) centre += r.lattice.points().row(p).transpose() / 4.0;
    // The boundary shrinks towards its limit surface (by less than a third of
    // a cell here), so the test box is the control face grown by 0.35 mm.
    EXPECT_TRUE((centre.array() >= low.array() - 0.35).all() && (centre.array() <= high.array() + 0.35).all())
        << "refined face " << f << " is not on control face " << origin;
  }
  for (int f = 0; f < cube3.faceCount(); ++f) EXPECT_EQ(perFace[f], cube3.isBoundaryFace(f) ? 16 : 0);
  // 64 refined cells (4^3) in each control cell, inside its cube.
  std::vector<int> perCell(cube3.cellCount(), 0);
  for (int c : r.cellOrigin) ++perCell[c];
  for (int n : perCell) EXPECT_EQ(n, 64);
}

TEST(Sculpting, TheRopePullsAGrabbedPointAndTheFixedBaseStays) {
  const Lattice cube3 = regularLattice(2, 2, 2);
  Sculpture s(cube3);
  s.fix(base(cube3));
  s.grab(Vector3(2, 2, 2));
  ASSERT_TRUE(s.roped());
  const int point = s.model().ropePoint();
  const Vector3 start = s.model().dataPoints().row(point).transpose();
  s.pullTo(start + Vector3(0.5, 0.5, 1.0));
  s.run(1000);
  const Vector3 end = s.model().dataPoints().row(point).transpose();
  EXPECT_GT((end - start).dot(Vector3(0.5, 0.5, 1.0).normalized()), 0.3) << "the rope did not pull the point";
  for (int i : base(cube3)) EXPECT_EQ(s.model().controlPoints().row(i), cube3.points().row(i));
  s.release();
  EXPECT_FALSE(s.roped());
  settle(s);
  EXPECT_LT(largestMove(s.model().controlPoints(), cube3.points()), kSettled) << "the elastic solid did not come back";
  EXPECT_THROW(s.pullTo(Vector3(0, 0, 0)), Error);
  EXPECT_THROW(s.grab(Vector3(std::nan(""), 0, 0)), Error);
}

TEST(Sculpting, PlasticityKeepsTheSculptedShape) {
  const Lattice cube3 = regularLattice(2, 2, 2);
  Sculpture s(cube3);
  holdAndPull(s, Vector3(2.5, 2.5, 3.0), 1000);
  s.plasticity();
  const MatrixX3 sculpted = s.model().controlPoints();
  EXPECT_EQ(s.rest().points(), sculpted);
  s.release();
  settle(s);
  // Still to within the motion left when the rest shape was taken (the
  // solid was near, not at, equilibrium under the rope).
  EXPECT_LT(largestMove(s.model().controlPoints(), sculpted), 0.02);
  EXPECT_GT(largestMove(s.model().controlPoints(), cube3.points()), 0.3) << "the sculpted shape was lost";
}

TEST(Sculpting, ExtrudeAndDeleteKeepTheRestShapeAndTheFixedPoints) {
  const Lattice cube3 = regularLattice(2, 2, 2);
  Sculpture s(cube3);
  // Extrude the top face of the cell at the far corner while the rope holds
  // the solid out of shape; then let go: the grown solid returns to the
  // extruded rest shape, with the base still where it was.
  holdAndPull(s, Vector3(2.6, 2.4, 2.8), 500);
  const int top = s.boundaryFaceNear(Vector3(1.5, 1.5, 2.0));
  const MatrixX3 heldBefore = s.model().controlPoints();
  const int outer = s.extrude(top);
  EXPECT_FALSE(s.roped()) << "a topology change releases the rope";
  EXPECT_EQ(s.control().cellCount(), 9);
  EXPECT_EQ(s.model().controlPoints().topRows(27), heldBefore) << "extrusion moved the existing points";
  for (int i : base(cube3)) EXPECT_TRUE(s.model().fixed()[i]);
  const Lattice extrudedRest = extrudeFace(cube3, top);
  EXPECT_EQ(s.rest().points(), extrudedRest.points());
  settle(s);
  EXPECT_LT(largestMove(s.model().controlPoints(), extrudedRest.points()), kSettled);
  // The new cell reaches one cell higher than the cube; its outer face is on top.
  EXPECT_NEAR(s.control().points().col(2).maxCoeff(), 3.0, kSettled);
  const Lattice grown = s.control();
  for (int p : grown.faces()[outer]) EXPECT_NEAR(grown.points()(p, 2), 3.0, kSettled);
  EXPECT_TRUE(grown.isBoundaryFace(outer));

  // Delete the cell under the new one's neighbour; the fixed base points it
  // used are renumbered and stay fixed.
  const int corner = s.cellNear(Vector3(0.5, 0.5, 0.5));
  std::vector<int> kept;
  const Lattice expected = deleteCell(s.control(), corner, &kept);
  s.deleteCell(corner);
  EXPECT_EQ(s.control().cellCount(), 8);
  EXPECT_LT(largestMove(s.control().points(), expected.points()), 1e-12);
  // The faces it shared with its neighbours came to the surface facing out.
  for (int f = 0; f < expected.faceCount(); ++f) {
    if (!expected.isBoundaryFace(f)) continue;
    EXPECT_TRUE(facesAwayFrom(expected, f, expected.faceCells()[f][0])) << "boundary face " << f << " faces inwards";
  }
  int fixedAfter = 0;
  for (bool f : s.model().fixed()) fixedAfter += f;
  EXPECT_EQ(fixedAfter, 8) << "9 base points less the one only the deleted cell used";
  settle(s);
  EXPECT_LT(largestMove(s.model().controlPoints(), expected.points()), kSettled);

  EXPECT_THROW(s.extrude(s.control().faceCount()), Error);
  EXPECT_THROW(s.deleteCell(-1), Error);
  EXPECT_THROW(s.fix({1000}), Error);
}

TEST(Sculpting, StiffnessAndDampingChangeWhileRunning) {
  const Lattice cube3 = regularLattice(2, 2, 2);
  Sculpture soft(cube3), stiff(cube3);
  for (Sculpture* s : {&soft, &stiff}) holdAndPull(*s, Vector3(2.5, 2.5, 3.0), 100);
  SolidMaterial m = stiff.settings().material;
  m.springStiffness *= 4;
  m.virtualStiffness *= 4;
  stiff.setMaterial(m);
  soft.run(2000);
  stiff.run(2000);
  const int point = soft.model().ropePoint();
  const Vector3 target(2.5, 2.5, 3.0);
  // The stiffer solid resists the same rope more.
  EXPECT_GT((stiff.model().dataPoints().row(point).transpose() - target).norm(),
            (soft.model().dataPoints().row(point).transpose() - target).norm() + 0.05);
  m.damping = -1;
  EXPECT_THROW(stiff.setMaterial(m), Error);
  EXPECT_THROW(Sculpture(cube3, SculptSettings{5, {}}), Error);
}

class SculptScripts : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (std::filesystem::temp_directory_path() /
             ("dynsub_sculpt_" + std::to_string(::getpid()) + "_" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".txt"))
                .string();
  }
  void TearDown() override { std::filesystem::remove(path_); }
  void write(const std::string& text) { std::ofstream(path_) << text; }
  // The message of the Error reading (and running) the script throws.
  std::string failure(const std::string& text) {
    write(text);
    try {
      Sculpture s(regularLattice(2, 2, 2));
      runSculptScript(readSculptScript(path_), s, path_);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
  std::string path_;
};

TEST_F(SculptScripts, EveryToolRunsFromAScript) {
  write(
      "# hold the base, pull a corner, keep the shape\n"
      "fix 0 1 2 3 4 5 6 7 8\n"
      "rope 2 2 2 to 2.5 2.5 3\n"
      "run 300\n"
      "pull 2.6 2.6 3.2\n"
      "  run 300   \n"
      "plasticity\n"
      "release\n"
      "stiffness 60 30\n"
      "damping 2\n"
      "extrude at 0.5 0.5 2\n"
      "extrude 0\n"
      "delete at 1.5 1.5 0.5\n"
      "unfix face 0\n"
      "fix face 0\n"
      "unfix all\n"
      "fix 0\n"
      "run 10\n");
  const std::vector<SculptAction> actions = readSculptScript(path_);
  ASSERT_EQ(actions.size(), 17u);
  EXPECT_EQ(actions[4].line, 6);
  EXPECT_EQ(actions[4].text, "run 300   ");
  Sculpture s(regularLattice(2, 2, 2));
  int done = 0;
  runSculptScript(actions, s, path_, [&](const SculptAction&) { ++done; });
  EXPECT_EQ(done, 17);
  EXPECT_EQ(s.steps(), 610);
  EXPECT_EQ(s.control().cellCount(), 8 + 2 - 1);
  EXPECT_EQ(s.settings().material.springStiffness, 60);
  EXPECT_EQ(s.settings().material.virtualStiffness, 30);
  EXPECT_EQ(s.settings().material.damping, 2);
  EXPECT_FALSE(s.roped());
  int fixed = 0;
  for (bool f : s.model().fixed()) fixed += f;
  EXPECT_EQ(fixed, 1);
  EXPECT_GT(s.rest().points().col(2).maxCoeff(), 2.5) << "the plastic pull and the extrusion raised the top";
}

TEST_F(SculptScripts, MistakesNameTheFileAndTheLine) {
  auto expectFailure = [&](const std::string& text, const std::string& fragment) {
    const std::string message = failure(text);
    EXPECT_NE(message.find(path_), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << message;
  };
  expectFailure("run 10\nsqueeze 3\n", "line 2: unknown action 'squeeze'");
  expectFailure("rope 1 2 3 4 5 6\n", "line 1: expected 'rope X Y Z to TX TY TZ'");
  expectFailure("# c\n\nrope 1 2 nan to 1 2 3\n", "line 3: coordinate must be a finite number, not 'nan'");
  expectFailure("run -4\n", "line 1: step count must be a whole number");
  expectFailure("run 2.5\n", "line 1: step count must be a whole number");
  expectFailure("extrude 3 4\n", "line 1: unexpected '4'");
  expectFailure("stiffness 0\n", "line 1: stiffness must be > 0");
  expectFailure("damping -1\n", "line 1: damping must be >= 0");
  expectFailure("fix\n", "line 1: expected control point indices");
  expectFailure("# nothing\n", "the script has no actions");
  // Errors of the tools themselves, while running, name the line and action.
  expectFailure("run 1\nextrude 1000\n", "line 2 (extrude 1000): ");
  expectFailure("fix 27\n", "line 1 (fix 27): no control point 27");
  expectFailure("fix face 99\n", "line 1 (fix face 99): no face 99");
  expectFailure("pull 1 1 1\n", "line 1 (pull 1 1 1): there is no rope");
  // A syntax error late in the script stops it before anything runs.
  write("run 10\nrun ten\n");
  EXPECT_THROW(readSculptScript(path_), Error);
  std::filesystem::remove(path_);
  try {
    readSculptScript(path_);
    ADD_FAILURE() << "a missing script was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path_ + ": no such file"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dynsub
