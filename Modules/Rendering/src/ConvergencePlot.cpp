#include "dynsub/ConvergencePlot.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include "dynsub/Error.h"

namespace dynsub {

namespace {

vtkSmartPointer<vtkTable> twoColumns(const char* x, const char* y, const std::vector<double>& xs,
                                     const std::vector<double>& ys) {
  auto table = vtkSmartPointer<vtkTable>::New();
  vtkNew<vtkDoubleArray> xColumn, yColumn;
  xColumn->SetName(x);
  yColumn->SetName(y);
  for (std::size_t i = 0; i < xs.size(); ++i) {
    xColumn->InsertNextValue(xs[i]);
    yColumn->InsertNextValue(ys[i]);
  }
  table->AddColumn(xColumn);
  table->AddColumn(yColumn);
  return table;
}

}  // namespace

vtkSmartPointer<vtkChartXY> convergenceChart(const ConvergenceHistory& history) {
  if (history.samples.empty()) throw Error("the convergence history is empty");
  // Steps counted over all levels; a refinement starts where the level changes.
  std::vector<double> steps, energies, errorSteps, errors, refinements;
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  int offset = 0, previousLevel = history.samples.front().level, previousStep = 0;
  for (const ConvergenceSample& s : history.samples) {
    if (s.level != previousLevel) {
      offset += previousStep;
      refinements.push_back(offset + 0.5);
      previousLevel = s.level;
    }
    previousStep = s.step;
    steps.push_back(offset + s.step);
    energies.push_back(s.energy);
    lowest = std::min(lowest, s.energy);
    highest = std::max(highest, s.energy);
    if (std::isfinite(s.fitError)) {
      errorSteps.push_back(offset + s.step);
      errors.push_back(s.fitError);
    }
  }
  const bool logarithmic = lowest > 0 && highest / lowest > 10;

  auto chart = vtkSmartPointer<vtkChartXY>::New();
  chart->SetTitle("Convergence");
  chart->GetTitleProperties()->SetFontSize(16);
  chart->SetShowLegend(true);
  chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
  chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);

  // A series of one point (a run that ended at its first step, or measured
  // its fit once) is a marker: VTK refuses to draw a line through one point.
  const auto kindFor = [](std::size_t points) { return points < 2 ? vtkChart::POINTS : vtkChart::LINE; };
  vtkPlot* energy = chart->AddPlot(kindFor(steps.size()));
  energy->SetInputData(twoColumns("step", "energy (N mm)", steps, energies), 0, 1);
  energy->SetColor(40, 90, 200, 255);
  energy->SetWidth(2.0);

  if (!errors.empty()) {
    vtkPlot* error = chart->AddPlot(kindFor(errors.size()));
    error->SetInputData(twoColumns("step", history.fitErrorName.c_str(), errorSteps, errors), 0, 1);
    error->SetColor(220, 80, 30, 255);
    error->SetWidth(2.0);
    chart->SetPlotCorner(error, 1);  // bottom-right: the right axis
    chart->GetAxis(vtkAxis::RIGHT)->SetTitle(history.fitErrorName);
  }

  // Refinement marks span the energy axis's range.
  const double bottom = logarithmic ? lowest : std::min(lowest, 0.0), top = highest;
  for (std::size_t r = 0; r < refinements.size(); ++r) {
    vtkPlot* mark = chart->AddPlot(vtkChart::LINE);
    mark->SetInputData(twoColumns("step", "refinement", {refinements[r], refinements[r]}, {bottom, top}), 0, 1);
    mark->SetColor(90, 90, 90, 255);
    mark->SetWidth(1.5);
    mark->GetPen()->SetLineType(vtkPen::DASH_LINE);
    mark->SetLegendVisibility(r == 0);
  }

  vtkAxis* left = chart->GetAxis(vtkAxis::LEFT);
  left->SetTitle("energy (N mm)");
  left->SetLogScale(logarithmic);
  chart->GetAxis(vtkAxis::BOTTOM)->SetTitle("step (all levels)");
  return chart;
}

}  // namespace dynsub
