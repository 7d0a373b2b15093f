#pragma once
// Sculpting a subdivision solid as virtual clay (McDonnell and Qin §5.4): a
// dynamic solid (SolidDynamics.h) and the tools that act on it, the same for
// the interactive window and for scripts.
//
//   rope        grab the mass point nearest a point and pull it by a spring
//               towards a target that follows the hand
//   extrude     grow a new cell on a boundary face of the control lattice
//   delete      remove a cell of the control lattice
//   fix, unfix  hold control points where they are (§5.2)
//   plasticity  the current shape becomes the rest shape
//   material    stiffness and damping, changed while the solid moves
//
// Extrude and delete change the topology, so the dynamic model is rebuilt on
// the new lattice. The rest shape goes through the same change (the tool is
// applied to the rest lattice too), so a solid that is held out of shape stays
// so and keeps its elastic memory; the motion stops, the rope is released and
// the fixed points keep being fixed.
#include <memory>
#include <vector>

#include "dynsub/SolidDynamics.h"

namespace dynsub {

struct SculptSettings {
  int levels = 2;  // subdivisions of the control lattice that carry the mass points (0..4)
  SolidMaterial material;
  double timeStep = 0.01;  // s; stable for the default material (SolidDynamicsTests)
  SolidScheme scheme = SolidScheme::SemiImplicit;
  double ropeStiffness = 40.0;  // N/mm
};

class Sculpture {
 public:
  // Throws dynsub::Error for impossible settings (level, material, step).
  explicit Sculpture(const Lattice& control, const SculptSettings& settings = {});
  ~Sculpture();

  const SolidModel& model() const { return *model_; }
  const SculptSettings& settings() const { return settings_; }
  // The control lattice at its current shape (what sculpting saves).
  Lattice control() const;
  // The control lattice at its rest shape.
  const Lattice& rest() const { return rest_; }
  int steps() const { return steps_; }  // time steps taken so far

  // The rope. grab fastens it to the mass point nearest `near`, with its free
  // end there; pullTo moves the free end. Throws dynsub::Error for a
  // non-finite point, or pullTo without a rope.
  void grab(const Vector3& near);
  void pullTo(const Vector3& target);
  void release();
  bool roped() const { return model_->ropePoint() >= 0; }

  // Throws dynsub::Error naming the face (not on the boundary) or the cell
  // (the last one), as Lattice.h's tools do. extrude returns the new cell's
  // outer face (opposite `face`), where extruding again continues the arm.
  int extrude(int face);
  void deleteCell(int cell);

  // Throws dynsub::Error for an index out of range.
  void fix(const std::vector<int>& points);
  void unfix(const std::vector<int>& points);
  void unfixAll();

  void plasticity();
  // Throws dynsub::Error for non-positive stiffness or mass, negative damping.
  void setMaterial(const SolidMaterial& material);

  // `count` time steps. Throws dynsub::Error if the simulation diverges (the
  // state stays the last finite one).
  void run(int count);

  // The control element nearest a point (for tools given a position):
  // the boundary face, or the cell, whose centroid at the current shape is nearest.
  int boundaryFaceNear(const Vector3& point) const;
  int cellNear(const Vector3& point) const;

 private:
  // A new model on `rest`, at `current`, with `fixed` carried over.
  void rebuild(const Lattice& rest, const MatrixX3& current, const std::vector<int>& fixed);

  SculptSettings settings_;
  Lattice rest_;
  std::unique_ptr<SolidModel> model_;
  int steps_ = 0;
};

}  // namespace dynsub
