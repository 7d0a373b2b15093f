#include "dynsub/SceneStyle.h"

#include <algorithm>
#include <cmath>

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCoordinate.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPolyDataMapper.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>

#include "dynsub/Error.h"

namespace dynsub::style {

void colourByElementType(vtkPolyDataMapper* mapper) {
  vtkNew<vtkLookupTable> table;
  table->SetNumberOfTableValues(2);
  table->SetTableRange(0, 1);
  table->SetTableValue(0, kNormalElement[0], kNormalElement[1], kNormalElement[2]);
  table->SetTableValue(1, kSpecialElement[0], kSpecialElement[1], kSpecialElement[2]);
  table->Build();
  mapper->SetLookupTable(table);
  mapper->SetColorModeToMapScalars();  // the array is unsigned char: not colours themselves
  mapper->SetScalarModeToUseCellFieldData();
  mapper->SelectColorArray("ElementType");
  mapper->SetScalarRange(0, 1);
  mapper->ScalarVisibilityOn();
}

namespace {

// The distance colours from `low` to colours.far, grey below `low`.
vtkSmartPointer<vtkLookupTable> distanceTable(const DistanceColours& colours, double low) {
  auto table = vtkSmartPointer<vtkLookupTable>::New();
  const Vector3 stops[3] = {Vector3(kNearColour.data()), Vector3(kMiddleColour.data()), Vector3(kFarColour.data())};
  constexpr int kEntries = 64;
  table->SetNumberOfTableValues(kEntries);
  table->SetTableRange(low, colours.far);
  for (int e = 0; e < kEntries; ++e) {
    const double distance = low + (colours.far - low) * e / (kEntries - 1);
    const double t = 2.0 * std::clamp((distance - colours.near) / (colours.far - colours.near), 0.0, 1.0);
    const int from = std::min(static_cast<int>(t), 1);
    const Vector3 c = stops[from] + (t - from) * (stops[from + 1] - stops[from]);
    table->SetTableValue(e, c.x(), c.y(), c.z(), 1.0);
  }
  table->SetBelowRangeColor(0.55, 0.55, 0.55, 1.0);  // -1: outside the region, unknown
  table->UseBelowRangeColorOn();
  return table;
}

}  // namespace

void colourByDistance(vtkPolyDataMapper* mapper, const DistanceColours& colours) {
  if (!(std::isfinite(colours.far) && colours.near >= 0.0 && colours.near < colours.far))
    throw Error("internal: distance colours need 0 <= near < far, both finite");
  // The range starts a little below 0: a distance of exactly 0 at its very
  // end is drawn, fragment by fragment, in the below-range grey of the
  // unknown as often as in green (a surface on its scan came out mottled).
  const double low = -0.01 * colours.far;
  mapper->SetLookupTable(distanceTable(colours, low));
  mapper->SetColorModeToMapScalars();
  mapper->SetScalarModeToUsePointFieldData();
  mapper->SelectColorArray(colours.array.c_str());
  mapper->SetScalarRange(low, colours.far);
  // Mapped per fragment, not per vertex: a triangle between a held and
  // an unknown point would otherwise blend green into grey.
  mapper->InterpolateScalarsBeforeMappingOn();
  mapper->ScalarVisibilityOn();
}

vtkSmartPointer<vtkScalarBarActor> distanceBar(const DistanceColours& colours) {
  auto bar = vtkSmartPointer<vtkScalarBarActor>::New();
  bar->SetLookupTable(distanceTable(colours, 0.0));  // labelled from 0
  bar->SetTitle(("mm to " + colours.to).c_str());
  // 0, the middle and the end: for a scan the middle is where green ends
  // (scanDistanceColours).
  bar->SetNumberOfLabels(3);
  bar->SetLabelFormat("%.3g");  // a scan's far distance may be a fraction of a mm
  bar->SetOrientationToVertical();
  bar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  bar->GetPositionCoordinate()->SetValue(0.84, 0.1);
  bar->SetWidth(0.1);
  bar->SetHeight(0.5);
  bar->UnconstrainedFontSizeOn();
  bar->GetTitleTextProperty()->SetFontSize(kFontSize);
  bar->GetLabelTextProperty()->SetFontSize(kFontSize);
  bar->GetTitleTextProperty()->ItalicOff();
  bar->GetLabelTextProperty()->ItalicOff();
  bar->GetTitleTextProperty()->ShadowOff();
  bar->GetLabelTextProperty()->ShadowOff();
  return bar;
}

void pointsAsDots(vtkActor* actor, double pixels) {
  actor->GetProperty()->SetRepresentationToPoints();
  actor->GetProperty()->SetPointSize(pixels);
  actor->GetProperty()->RenderPointsAsSpheresOn();
  actor->GetProperty()->LightingOff();
}

vtkSmartPointer<vtkPolyData> dots(const MatrixX3& points, const std::vector<int>& rows, int selected) {
  vtkNew<vtkPoints> positions;
  vtkNew<vtkCellArray> vertices;
  vtkNew<vtkUnsignedCharArray> colours;
  colours->SetNumberOfComponents(3);
  for (int r : rows) {
    const vtkIdType id = positions->InsertNextPoint(points(r, 0), points(r, 1), points(r, 2));
    vertices->InsertNextCell(1, &id);
    if (selected >= -1) colours->InsertNextTypedTuple((r == selected ? kSelectedLandmark : kLandmark).data());
  }
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->SetPoints(positions);
  data->SetVerts(vertices);
  if (selected >= -1) data->GetPointData()->SetScalars(colours);
  return data;
}

std::vector<int> allRows(const MatrixX3& points) {
  std::vector<int> rows(points.rows());
  for (int r = 0; r < static_cast<int>(rows.size()); ++r) rows[r] = r;
  return rows;
}

void showLandmarks(vtkRenderer* renderer, vtkPolyData* points, vtkActor* actor) {
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(points);
  actor->SetMapper(mapper);
  pointsAsDots(actor, kLandmarkPixels);
  renderer->AddActor(actor);
}

namespace {

void showPlainDots(vtkRenderer* renderer, vtkPolyData* points, vtkActor* actor, const std::array<double, 3>& colour,
                   double pixels) {
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(points);
  mapper->ScalarVisibilityOff();
  actor->SetMapper(mapper);
  pointsAsDots(actor, pixels);
  actor->GetProperty()->SetColor(colour[0], colour[1], colour[2]);
  renderer->AddActor(actor);
}

}  // namespace

void showDataPoints(vtkRenderer* renderer, vtkPolyData* points, vtkActor* actor) {
  showPlainDots(renderer, points, actor, kDataPoint, kDataPixels);
}

void showOutliers(vtkRenderer* renderer, vtkPolyData* points, vtkActor* actor) {
  showPlainDots(renderer, points, actor, kOutlierPoint, kOutlierPixels);
}

vtkSmartPointer<vtkRenderWindow> offScreenWindow(int width, int height) {
  auto window = vtkSmartPointer<vtkRenderWindow>::New();
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(width, height);
  return window;
}

std::size_t textColumns(double pixels, int fontSize) {
  return static_cast<std::size_t>(std::max(20.0, pixels / (0.55 * fontSize)));
}

void cornerText(vtkTextActor* text, double x, double y, Corner corner, int fontSize) {
  text->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  text->SetPosition(x, y);
  vtkTextProperty* p = text->GetTextProperty();
  p->SetFontSize(fontSize);
  p->SetFontFamilyToArial();
  p->SetColor(1, 1, 1);
  p->SetJustificationToCentered();
  p->SetVerticalJustificationToCentered();
  switch (corner) {
    case Corner::TopLeft: p->SetJustificationToLeft(); p->SetVerticalJustificationToTop(); break;
    case Corner::TopRight: p->SetJustificationToRight(); p->SetVerticalJustificationToTop(); break;
    case Corner::BottomLeft: p->SetJustificationToLeft(); p->SetVerticalJustificationToBottom(); break;
    case Corner::BottomRight: p->SetJustificationToRight(); p->SetVerticalJustificationToBottom(); break;
    case Corner::Left: p->SetJustificationToLeft(); break;
    case Corner::Right: p->SetJustificationToRight(); break;
    case Corner::Top: p->SetVerticalJustificationToTop(); break;
    case Corner::Bottom: p->SetVerticalJustificationToBottom(); break;
  }
}

void helpOverlay(vtkRenderer* overlay, vtkTextActor* text, const char* help, double x, double y) {
  cornerText(text, x, y, Corner::TopLeft, 13);
  text->SetInput(help);
  text->GetTextProperty()->SetBackgroundColor(0, 0, 0);
  text->GetTextProperty()->SetBackgroundOpacity(0.7);
  text->VisibilityOff();
  overlay->AddActor2D(text);
}

void observeTimer(vtkRenderWindowInteractor* interactor, vtkCallbackCommand* command, void (*tick)(void* client),
                  void* client) {
  // The callback gets one pointer: the client's, with `tick` kept beside it.
  struct Tick {
    void (*tick)(void*);
    void* client;
  };
  auto* data = new Tick{tick, client};
  command->SetClientData(data);
  command->SetClientDataDeleteCallback([](void* d) { delete static_cast<Tick*>(d); });
  command->SetCallback([](vtkObject*, unsigned long, void* d, void*) {
    const auto* t = static_cast<Tick*>(d);
    t->tick(t->client);
  });
  interactor->AddObserver(vtkCommand::TimerEvent, command);
}

Vector3 displayAt(vtkRenderer* renderer, const Vector3& world) {
  renderer->SetWorldPoint(world.x(), world.y(), world.z(), 1.0);
  renderer->WorldToDisplay();
  double display[3];
  renderer->GetDisplayPoint(display);
  return {display[0], display[1], display[2]};
}

Vector3 worldAt(vtkRenderer* renderer, double x, double y, double depth) {
  renderer->SetDisplayPoint(x, y, depth);
  renderer->DisplayToWorld();
  double world[4];
  renderer->GetWorldPoint(world);
  return {world[0] / world[3], world[1] / world[3], world[2] / world[3]};
}

std::string anatomicalLetter(const Vector3& direction) {
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(direction[a]) > std::abs(direction[axis])) axis = a;
  static const char* positive[3] = {"L", "P", "S"};
  static const char* negative[3] = {"R", "A", "I"};
  return direction[axis] >= 0 ? positive[axis] : negative[axis];
}

}  // namespace dynsub::style
