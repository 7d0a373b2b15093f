#pragma once
// Shape recovery from range data (TVCG 1998 §4.2; ICCV 1998 §3-4): springs
// from every data point to its nearest point on the limit surface pull an
// initial model, inside the data, onto the data; at each equilibrium the fit
// error is measured and, while it is above the tolerance, the control mesh is
// refined globally (Simulation.h).
//
// Fit error (the papers' measure): the distance from each data point to the
// exact limit surface (ClosestPoint.h), as a percentage of the diameter of the
// smallest sphere enclosing the data (EnclosingSphere.h); max_error_percent
// is the largest, rms_error_percent the root mean square.
//
// Spring stiffness: every data point gets k = dataStiffness x (parametric area
// of the initial model) / #points, so the balance between data and surface
// elasticity does not depend on how densely the data were sampled.
#include <memory>
#include <string>
#include <vector>

#include "dynsub/ControlMesh.h"
#include "dynsub/EnclosingSphere.h"
#include "dynsub/InitialModels.h"
#include "dynsub/Simulation.h"

namespace dynsub {

struct FitOptions {
  double tolerancePercent = 1.0;  // max_error_percent that stops refinement
  double dataStiffness = 100.0;   // N/mm per unit parametric area (see above)
  SimulationOptions simulation = defaultSimulation();

  static SimulationOptions defaultSimulation();
};

struct FitError {
  double maxPercent = 0;
  double rmsPercent = 0;
};

struct FitResult {
  ControlMesh mesh;
  std::shared_ptr<const LimitSurface> surface;  // mesh's limit surface (SimulationResult::surface)
  Sphere enclosingSphere;
  FitError error;
  std::vector<LevelSummary> levels;
  std::vector<FitError> levelErrors;  // one per level, where it ended
  int steps = 0;
  double seconds = 0;
};

FitError measureFitError(const LimitSurface& surface, const MatrixX3& controlPoints, const MatrixX3& data,
                         double diameter);

// `initial` must be closed. Throws dynsub::Error on bad input or divergence.
FitResult fitPointCloud(const MatrixX3& data, const ControlMesh& initial, const FitOptions& options,
                        const ProgressCallback& progress = nullptr);

}  // namespace dynsub
