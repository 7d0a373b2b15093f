// Dynamic subdivision solids: rest is an equilibrium, elastic solids return to
// their rest shape, the rope tool's motion is damped and stable, fixed control
// points stay, and resetting rest lengths makes a deformation permanent.
#include <gtest/gtest.h>

#include <iostream>

#include "dynsub/Error.h"
#include "dynsub/SolidDynamics.h"

namespace dynsub {
namespace {

constexpr double kStep = 0.01;  // s; the semi-implicit scheme is stable here for the default material

TEST(SolidDynamics, AFreeSolidUnderNoForceKeepsItsShape) {
  SolidModel model(regularLattice(2, 2, 2), 2);
  const MatrixX3 start = model.controlPoints();
  for (int i = 0; i < 500; ++i) model.step(kStep);
  EXPECT_LT((model.controlPoints() - start).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(model.kineticEnergy(), 1e-20);  // rest lengths are lengths to rounding
}

TEST(SolidDynamics, AnElasticSolidReturnsToItsRestShape) {
  // A solid at rest, pulled out of shape by the rope and released.
  SolidModel rest(regularLattice(2, 2, 2), 2);
  const int corner = rest.nearestDataPoint(Vector3(2, 2, 2));
  rest.rope(corner, Vector3(2.8, 2.8, 2.8), 40.0);
  for (int i = 0; i < 300; ++i) rest.step(kStep);
  const double stretched = rest.springEnergy();
  ASSERT_GT(stretched, 1e-3);
  rest.releaseRope();
  for (int i = 0; i < 4000; ++i) rest.step(kStep);
  EXPECT_LT(rest.springEnergy(), 1e-6 * stretched) << "the solid did not return to rest";
  EXPECT_LT(rest.kineticEnergy(), 1e-9);
}

TEST(SolidDynamics, TheRopeToolsMotionIsDampedAndStable) {
  for (SolidScheme scheme : {SolidScheme::SemiImplicit, SolidScheme::PaperExplicit}) {
    SCOPED_TRACE(scheme == SolidScheme::SemiImplicit ? "semi-implicit" : "paper explicit");
    // The paper's explicit Euler needs a smaller step.
    const double dt = scheme == SolidScheme::SemiImplicit ? kStep : kStep / 2;
    // Held at its base, as when sculpting (a free solid would mostly drift
    // towards the rope, slowed only by the damping of all its mass).
    SolidModel model(regularLattice(2, 2, 2), 2);
    std::vector<int> base;
    for (int i = 0; i < model.control().pointCount(); ++i)
      if (model.control().points()(i, 2) == 0.0) base.push_back(i);
    model.fix(base);
    const int corner = model.nearestDataPoint(Vector3(2, 2, 2));
    const Vector3 target(3, 3, 3);
    const double before = (model.dataPoints().row(corner).transpose() - target).norm();
    model.rope(corner, target, 40.0);
    double peak = 0;
    const int steps = static_cast<int>(12.0 / dt);  // 12 s of motion
    for (int i = 0; i < steps; ++i) {
      model.step(dt, scheme);
      peak = std::max(peak, model.kineticEnergy());
    }
    const double after = (model.dataPoints().row(corner).transpose() - target).norm();
    EXPECT_LT(after, 0.8 * before) << "the rope did not pull the corner";
    EXPECT_LT(model.kineticEnergy(), 1e-4 * peak) << "the motion did not settle under the rope";
    // Released, the solid springs back: its energy (kinetic + springs) must
    // only fall, as damping takes it (a growing energy would be the scheme's).
    model.releaseRope();
    const double released = model.kineticEnergy() + model.springEnergy();
    double highest = 0, settled = 0;
    for (int i = 0; i < 3 * steps; ++i) {
      model.step(dt, scheme);
      highest = std::max(highest, model.kineticEnergy() + model.springEnergy());
    }
    settled = model.kineticEnergy() + model.springEnergy();
    // Forward Euler (the paper's) adds energy of order dt * frequency per
    // step, which damping outweighs only over a swing: 1 % allowed there.
    EXPECT_LE(highest, (scheme == SolidScheme::SemiImplicit ? 1.001 : 1.01) * released)
        << "the energy grew after release";
    EXPECT_LT(settled, 1e-4 * released) << "the solid did not come back to rest";
    EXPECT_TRUE(model.controlPoints().allFinite());
    std::cout << "rope: corner from " << before << " to " << after << " mm of the target; energy at release "
              << released << ", highest after " << highest << ", after 36 s " << settled << '\n';
  }
}

TEST(SolidDynamics, FixedControlPointsStayAndPlasticityKeepsTheShape) {
  SolidModel model(regularLattice(2, 2, 2), 2);
  std::vector<int> bottom;
  for (int i = 0; i < model.control().pointCount(); ++i)
    if (model.control().points()(i, 2) == 0.0) bottom.push_back(i);
  ASSERT_EQ(bottom.size(), 9u);
  model.fix(bottom);
  const MatrixX3 start = model.controlPoints();
  model.rope(model.nearestDataPoint(Vector3(2, 2, 2)), Vector3(2.5, 2.5, 3.0), 40.0);
  for (int i = 0; i < 600; ++i) model.step(kStep);
  for (int i : bottom) EXPECT_EQ((model.controlPoints().row(i) - start.row(i)).norm(), 0.0);
  EXPECT_GT((model.controlPoints() - start).cwiseAbs().maxCoeff(), 0.1);
  // Plasticity: the pulled shape becomes the rest shape and stays after release.
  model.resetRestLengths();
  model.releaseRope();
  const MatrixX3 pulled = model.controlPoints();
  for (int i = 0; i < 600; ++i) model.step(kStep);
  EXPECT_LT((model.controlPoints() - pulled).cwiseAbs().maxCoeff(), 0.02);
  // Stiffness and damping change while running; the state stays finite.
  SolidMaterial softer = model.material();
  softer.springStiffness = 10;
  softer.damping = 1;
  model.setMaterial(softer);
  for (int i = 0; i < 100; ++i) model.step(kStep);
  EXPECT_TRUE(model.controlPoints().allFinite());
  EXPECT_THROW(model.step(std::nan("")), Error);
  EXPECT_THROW(SolidModel(regularLattice(1, 1, 1), 9), Error);
}

TEST(SolidDynamics, ADivergingStepIsReportedAndTheStateKept) {
  SolidModel model(regularLattice(2, 2, 2), 1);
  model.rope(0, Vector3(-5, -5, -5), 1e6);
  const MatrixX3 before = model.controlPoints();
  bool thrown = false;
  for (int i = 0; i < 2000 && !thrown; ++i) {
    try {
      model.step(1.0, SolidScheme::PaperExplicit);
    } catch (const Error&) {
      thrown = true;
    }
  }
  EXPECT_TRUE(thrown) << "a step of 1 s with a 1e6 N/mm rope should diverge";
  EXPECT_TRUE(model.controlPoints().allFinite());
}

}  // namespace
}  // namespace dynsub
