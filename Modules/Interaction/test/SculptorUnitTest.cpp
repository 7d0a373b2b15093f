// The sculpting window (Sculptor.h) driven by recorded mouse and key events:
// every tool the window offers is used on Cube 3^3 and its effect checked on
// the sculpture. Needs an X display (ctest runs under xvfb-run).
#include <gtest/gtest.h>

#include <filesystem>

#include <vtkRenderWindow.h>
#include <vtkRenderer.h>

#include "EventStreams.h"
#include "dynsub/Error.h"
#include "dynsub/Figures.h"
#include "dynsub/Sculptor.h"
#include "dynsub/SolidView.h"

namespace dynsub {
namespace {

using events::key;
using events::mouse;

class SculptorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!displayAvailable(&why)) FAIL() << "sculptor tests need an X display: " << why;
  }
};

// Where a point (mm) is drawn in the sculptor's window.
Eigen::Vector2d displayOf(Sculptor& sculptor, const Vector3& point) {
  vtkRenderer* r = sculptor.view().renderer();
  r->SetWorldPoint(point.x(), point.y(), point.z(), 1.0);
  r->WorldToDisplay();
  return Eigen::Vector2d(r->GetDisplayPoint()[0], r->GetDisplayPoint()[1]);
}

int fixedCount(const Sculpture& s) {
  int n = 0;
  for (bool f : s.model().fixed()) n += f;
  return n;
}

void shiftClick(Sculptor& sculptor, const Vector3& at) {
  const Eigen::Vector2d p = displayOf(sculptor, at);
  events::play(sculptor.interactor(), {mouse("LeftButtonPressEvent", p, events::kShift),
                                       mouse("LeftButtonReleaseEvent", p, events::kShift)});
}

void press(Sculptor& sculptor, const char* keySym, char code) {
  events::play(sculptor.interactor(), {key(keySym, code)});
}

TEST_F(SculptorTest, EveryToolWorksFromTheMouseAndKeys) {
  const Lattice cube3 = regularLattice(2, 2, 2);
  int saves = 0;
  Sculptor sculptor(cube3, SculptSettings{}, [&](const Sculpture& s) {
    ++saves;
    return "saved " + std::to_string(s.control().cellCount()) + " cells";
  });
  sculptor.window()->Render();
  const Sculpture& s = sculptor.sculpture();

  // Select the top face of the back right cell by its centre.
  shiftClick(sculptor, Vector3(1.5, 1.5, 2.0));
  const int top = s.boundaryFaceNear(Vector3(1.5, 1.5, 2.0));
  ASSERT_EQ(sculptor.selectedFace(), top);
  EXPECT_NE(sculptor.status().find("face " + std::to_string(top) + " selected"), std::string::npos);

  // e twice: an arm of two cells; the selection follows its end.
  press(sculptor, "e", 'e');
  EXPECT_EQ(s.rest().cellCount(), 9);
  press(sculptor, "e", 'e');
  ASSERT_EQ(s.rest().cellCount(), 10);
  const int end = sculptor.selectedFace();
  for (int p : s.rest().faces()[end]) EXPECT_NEAR(s.rest().points()(p, 2), 4.0, 1e-12);

  // f / u / U on the selected face's points.
  press(sculptor, "f", 'f');
  EXPECT_EQ(fixedCount(s), 4);
  press(sculptor, "u", 'u');
  EXPECT_EQ(fixedCount(s), 0);
  press(sculptor, "f", 'f');
  press(sculptor, "U", 'U');
  EXPECT_EQ(fixedCount(s), 0);

  // A right click on a control point fixes it, a second frees it; elsewhere
  // it is the trackball's (nothing changes).
  const Vector3 corner = s.rest().points().row(0).transpose();
  const Eigen::Vector2d at = displayOf(sculptor, corner);
  events::play(sculptor.interactor(), {mouse("RightButtonPressEvent", at), mouse("RightButtonReleaseEvent", at)});
  EXPECT_TRUE(s.model().fixed()[0]);
  EXPECT_EQ(fixedCount(s), 1);
  events::play(sculptor.interactor(), {mouse("RightButtonPressEvent", at), mouse("RightButtonReleaseEvent", at)});
  EXPECT_EQ(fixedCount(s), 0);
  const Eigen::Vector2d away = at + Eigen::Vector2d(40, 40);
  events::play(sculptor.interactor(), {mouse("RightButtonPressEvent", away), mouse("RightButtonReleaseEvent", away)});
  EXPECT_EQ(fixedCount(s), 0);

  // d deletes the cell of the selected face (the arm's end); then nothing is selected.
  press(sculptor, "d", 'd');
  EXPECT_EQ(s.rest().cellCount(), 9);
  EXPECT_EQ(sculptor.selectedFace(), -1);
  press(sculptor, "d", 'd');
  EXPECT_EQ(s.rest().cellCount(), 9);
  EXPECT_NE(sculptor.status().find("select a face first"), std::string::npos);

  // k / K, g / G scale the material while it runs.
  const SolidMaterial before = s.settings().material;
  press(sculptor, "k", 'k');
  EXPECT_DOUBLE_EQ(s.settings().material.springStiffness, 0.8 * before.springStiffness);
  EXPECT_DOUBLE_EQ(s.settings().material.virtualStiffness, 0.8 * before.virtualStiffness);
  press(sculptor, "K", 'K');
  EXPECT_DOUBLE_EQ(s.settings().material.springStiffness, before.springStiffness);
  press(sculptor, "G", 'G');
  EXPECT_DOUBLE_EQ(s.settings().material.damping, 1.25 * before.damping);
  press(sculptor, "g", 'g');
  EXPECT_DOUBLE_EQ(s.settings().material.damping, before.damping);

  // space pauses the motion and resumes it; each tick is 40 ms of it.
  sculptor.advance(2);
  const int steps = s.steps();
  EXPECT_EQ(steps, 2 * 4);
  press(sculptor, "space", ' ');
  EXPECT_TRUE(sculptor.paused());
  sculptor.advance(3);
  EXPECT_EQ(s.steps(), steps);
  press(sculptor, "space", ' ');
  sculptor.advance(3);
  EXPECT_EQ(s.steps(), steps + 12);

  // p: the current shape is the rest shape.
  press(sculptor, "p", 'p');
  EXPECT_EQ(s.rest().points(), s.model().controlPoints());

  // w hides and shows the control lattice; s saves through the given action.
  press(sculptor, "w", 'w');
  EXPECT_FALSE(sculptor.view().controlLatticeShown());
  press(sculptor, "w", 'w');
  EXPECT_TRUE(sculptor.view().controlLatticeShown());
  press(sculptor, "s", 's');
  EXPECT_EQ(saves, 1);
  EXPECT_NE(sculptor.status().find("saved 9 cells"), std::string::npos);

  // The window with its help, for review: build/Testing/Temporary/SculptorWindow.png.
  press(sculptor, "h", 'h');
  const std::string temporary = std::string(DYNSUB_BINARY_DIR) + "/Testing/Temporary";
  std::filesystem::create_directories(temporary);
  writePng(sculptor.window(), temporary + "/SculptorWindow.png");
}

TEST_F(SculptorTest, CtrlDragPullsTheSolidByARopeAndReleasingLetsGo) {
  Sculptor sculptor(regularLattice(2, 2, 2), SculptSettings{}, nullptr);
  sculptor.window()->Render();
  const Sculpture& s = sculptor.sculpture();
  const Eigen::Vector2d from = displayOf(sculptor, Vector3(1.5, 1.5, 2.0));
  const Eigen::Vector2d to = from + Eigen::Vector2d(0, 120);  // straight up the screen
  events::play(sculptor.interactor(), {mouse("LeftButtonPressEvent", from, events::kCtrl)});
  ASSERT_TRUE(s.roped());
  const int point = s.model().ropePoint();
  const Vector3 start = s.model().dataPoints().row(point).transpose();
  EXPECT_LT((start - Vector3(1.5, 1.5, 2.0)).norm(), 0.5) << "the rope is not where the click was";
  events::play(sculptor.interactor(), {mouse("MouseMoveEvent", 0.5 * (from + to), events::kCtrl),
                                       mouse("MouseMoveEvent", to, events::kCtrl)});
  const Vector3 target = s.model().ropeTarget();
  EXPECT_NEAR((displayOf(sculptor, target) - to).norm(), 0.0, 1.0) << "the rope's end is not under the mouse";
  sculptor.advance(100);  // 4 s
  // A free solid follows slowly: the damping acts on every mass point (0.13 mm
  // of the 0.52 mm in 2 s, measured), so the test asks for a fifth of the way.
  const Vector3 pulled = s.model().dataPoints().row(point).transpose();
  EXPECT_LT((pulled - target).norm(), 0.8 * (start - target).norm()) << "the rope did not pull";
  events::play(sculptor.interactor(), {mouse("LeftButtonReleaseEvent", to, events::kCtrl)});
  EXPECT_FALSE(s.roped());
  // Without Ctrl the same drag turns the view, not the solid.
  events::play(sculptor.interactor(), {mouse("LeftButtonPressEvent", from), mouse("MouseMoveEvent", to),
                                       mouse("LeftButtonReleaseEvent", to)});
  EXPECT_FALSE(s.roped());
}

TEST_F(SculptorTest, ADivergingStepPausesWithAMessageAndKeepsAFiniteShape) {
  SculptSettings stiff;
  stiff.material.springStiffness = 1e6;
  stiff.ropeStiffness = 1e6;
  stiff.timeStep = 0.05;
  Sculptor sculptor(regularLattice(2, 2, 2), stiff, [](const Sculpture&) -> std::string {
    throw Error("out", "the disk is full");
  });
  sculptor.window()->Render();
  const Eigen::Vector2d from = displayOf(sculptor, Vector3(1.5, 1.5, 2.0));
  events::play(sculptor.interactor(), {mouse("LeftButtonPressEvent", from, events::kCtrl),
                                       mouse("MouseMoveEvent", from + Eigen::Vector2d(0, 150), events::kCtrl)});
  // Each step multiplies the error by about k dt^2 / m: overflow within 100 steps.
  sculptor.advance(200);
  EXPECT_TRUE(sculptor.paused());
  EXPECT_NE(sculptor.status().find("diverged"), std::string::npos) << sculptor.status();
  EXPECT_TRUE(sculptor.sculpture().model().controlPoints().allFinite());
  EXPECT_FALSE(sculptor.sculpture().roped());
  // A failing save says why in the status line.
  press(sculptor, "s", 's');
  EXPECT_NE(sculptor.status().find("out: the disk is full"), std::string::npos) << sculptor.status();
}

}  // namespace
}  // namespace dynsub
