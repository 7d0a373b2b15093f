#pragma once
// The convergence plot (VTK charts): the total energy of every step on the
// left axis (logarithmic when it stays positive), the fit error where measured
// on the right axis, against the step counted over all levels; a dashed
// vertical line marks each global refinement.
#include <vtkSmartPointer.h>

#include "dynsub/ConvergenceHistory.h"

class vtkChartXY;

namespace dynsub {

// Throws dynsub::Error for an empty history.
vtkSmartPointer<vtkChartXY> convergenceChart(const ConvergenceHistory& history);

}  // namespace dynsub
