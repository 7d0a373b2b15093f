#include "dynsub/Landmarks.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/TextFields.h"

namespace dynsub {
namespace {

enum class Format { MarkupsJson, Fcsv, Csv };

// .mrk.json (3D Slicer's name) ends in .json.
Format formatOf(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  if (extension == ".json") return Format::MarkupsJson;
  if (extension == ".fcsv") return Format::Fcsv;
  if (extension == ".csv") return Format::Csv;
  throw Error(path, "unknown landmark format (expected .mrk.json, .fcsv or .csv)");
}

// RAS <-> LPS is its own inverse.
Vector3 flipXY(const Vector3& p) { return Vector3(-p.x(), -p.y(), p.z()); }

// A column named twice leaves which of the two holds the value to chance.
void requireDistinctColumns(const std::string& path, int line, const std::vector<std::string>& columns) {
  for (std::size_t c = 0; c < columns.size(); ++c)
    for (std::size_t d = c + 1; d < columns.size(); ++d)
      if (!columns[c].empty() && columns[c] == columns[d])
        throw Error(path, "line " + std::to_string(line) + ": the column '" + columns[c] + "' is named twice");
}

// Where `name` stands among `columns`, or -1.
int columnIndex(const std::vector<std::string>& columns, const std::string& name) {
  const auto at = std::find(columns.begin(), columns.end(), name);
  return at == columns.end() ? -1 : static_cast<int>(at - columns.begin());
}

double finiteNumber(const std::string& text, const std::string& path, int line) {
  double value = 0;
  if (!parseNumber(text, value) || !std::isfinite(value))
    throw Error(path, "line " + std::to_string(line) + ": '" + text + "' is not a finite number");
  return value;
}

// The string `key` of a JSON object, or `fallback` when it has none: another
// JSON type (a number for a label) is an error that says where.
std::string textField(const nlohmann::json& object, const std::string& key, const std::string& fallback,
                      const std::string& path, const std::string& where) {
  if (!object.contains(key)) return fallback;
  const nlohmann::json& value = object[key];
  if (!value.is_string()) throw Error(path, where + ": \"" + key + "\" must be a string, got " + value.dump());
  return value.get<std::string>();
}

// Whether a markup's control points are points on a structure: a point
// list's, and a curve's drawn along its boundary. A line, an angle, a plane
// or an ROI (a ruler, a protractor, a cut, a box) is a measurement or a
// region kept in the same scene: it is left out. Another type is an error,
// so that a type this reader does not know is never read as landmarks.
bool onStructure(const std::string& path, const std::string& type) {
  if (type == "Fiducial" || type == "Curve" || type == "ClosedCurve") return true;
  if (type == "Line" || type == "Angle" || type == "Plane" || type == "ROI") return false;
  throw Error(path, "a markup of unknown type \"" + type +
                        "\" (point lists, curves and closed curves give landmarks; lines, angles, planes and ROIs are "
                        "left out)");
}

// A markups file's document, with its "markups" list.
nlohmann::json readMarkupsDocument(const std::string& path, std::ifstream& in) {
  nlohmann::json document;
  try {
    // Read to the end: text after the document (a file pasted twice, a
    // stray edit) is refused, not ignored.
    document = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, "not valid JSON: " + withoutLibraryTag(e.what()));
  }
  if (!document.contains("markups") || !document["markups"].is_array())
    throw Error(path, "no \"markups\" list (not a 3D Slicer markups file)");
  return document;
}

// Every point list and curve of a markups file's document, in order, with
// or without points.
std::vector<LandmarkList> markupsLists(const std::string& path, const nlohmann::json& document) {
  std::vector<LandmarkList> lists;
  std::vector<std::string> leftOut;  // the types of the markups that give no landmarks
  int markupNumber = 0;
  for (const auto& markup : document["markups"]) {
    const std::string where = "markup " + std::to_string(++markupNumber);
    if (!markup.is_object()) throw Error(path, where + " is not a JSON object");
    const std::string type = textField(markup, "type", "Fiducial", path, where);
    if (!onStructure(path, type)) {
      leftOut.push_back(type);
      continue;
    }
    const std::string system = textField(markup, "coordinateSystem", "LPS", path, where);
    if (system != "LPS" && system != "RAS") throw Error(path, "unknown coordinateSystem \"" + system + "\"");
    // Slicer writes a unit's name, or (schema 1.0.3) a list of its forms
    // whose first is the name: ["mm", "UCUM", "millimeter"].
    const nlohmann::json units = markup.contains("coordinateUnits") ? markup["coordinateUnits"] : nlohmann::json("mm");
    const nlohmann::json& unit = units.is_array() && !units.empty() ? units[0] : units;
    if (!unit.is_string() || unit.get<std::string>() != "mm")
      throw Error(path, where + ": coordinateUnits must be mm, got " + units.dump());
    LandmarkList& list = lists.emplace_back();
    list.name = textField(markup, "name", "", path, where);
    list.stated = system == "RAS" ? CoordinateSystem::RAS : CoordinateSystem::LPS;
    if (!markup.contains("controlPoints")) continue;
    if (!markup["controlPoints"].is_array()) throw Error(path, where + ": \"controlPoints\" must be a list");
    int index = 0;
    for (const auto& point : markup["controlPoints"]) {
      const std::string pointWhere = "control point " + std::to_string(++index);
      if (!point.is_object()) throw Error(path, pointWhere + " is not a JSON object");
      // Slicer's three states: a point placed, one being placed, and a
      // name waiting for its point (both left out).
      const std::string status = textField(point, "positionStatus", "defined", path, pointWhere);
      if (status != "defined" && status != "preview" && status != "undefined")
        throw Error(
            path, pointWhere + ": unknown positionStatus \"" + status + "\" (expected defined, preview or undefined)");
      if (status != "defined") continue;
      const auto& position = point.contains("position") ? point["position"] : nlohmann::json();
      if (!position.is_array() || position.size() != 3 || !position[0].is_number() || !position[1].is_number() ||
          !position[2].is_number())
        throw Error(path, pointWhere + " has no [x, y, z] position");
      Vector3 p(position[0].get<double>(), position[1].get<double>(), position[2].get<double>());
      if (!p.allFinite()) throw Error(path, pointWhere + " is not finite");
      list.landmarks.push_back(
          {textField(point, "label", "F-" + std::to_string(index), path, pointWhere), system == "RAS" ? flipXY(p) : p});
    }
  }
  // A file of measurements and regions alone (an ROI box, a plane) holds no
  // landmark: say so, rather than that the file has none.
  if (lists.empty() && !leftOut.empty()) {
    std::string types;
    for (const std::string& type : leftOut) types += (types.empty() ? "" : ", ") + type;
    throw Error(path, "no point list or curve: its markups (" + types +
                          ") are measurements or regions, which give no landmarks. Place the points as a point "
                          "list (Slicer's Markups, 'Point List')");
  }
  return lists;
}

std::vector<Landmark> readFcsv(const std::string& path, std::ifstream& in, CoordinateSystem& system) {
  std::vector<std::string> columns = {"id", "x", "y", "z", "ow", "ox", "oy", "oz", "vis", "sel", "lock", "label"};
  std::vector<Landmark> landmarks;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1) line = withoutByteOrderMark(line);
    if (line.empty() || line == "\r") continue;
    if (line[0] == '#') {
      const auto equals = line.find('=');
      if (equals == std::string::npos) continue;
      const std::string key = line.substr(0, equals), value = splitCsvFields(line.substr(equals + 1), ',')[0];
      const bool systemLine = key.find("CoordinateSystem") != std::string::npos;
      const bool columnsLine = key.find("columns") != std::string::npos;
      // Slicer writes its header before the points; one after them would
      // apply to some points and not to others.
      if ((systemLine || columnsLine) && !landmarks.empty())
        throw Error(path, "line " + std::to_string(number) + ": a header line ('" + trimmed(key.substr(1)) +
                              "') after the points: move it above them");
      if (systemLine) {
        if (value == "LPS" || value == "1")
          system = CoordinateSystem::LPS;
        else if (value == "RAS" || value == "0")
          system = CoordinateSystem::RAS;
        else
          throw Error(path, "line " + std::to_string(number) + ": unknown coordinate system '" + value + "'");
      } else if (columnsLine) {
        columns = splitCsvFields(line.substr(equals + 1), ',');
        requireDistinctColumns(path, number, columns);
      }
      continue;
    }
    const auto fields = splitCsvFields(line, ',');
    const int x = columnIndex(columns, "x"), y = columnIndex(columns, "y"), z = columnIndex(columns, "z"),
              label = columnIndex(columns, "label");
    if (x < 0 || y < 0 || z < 0) throw Error(path, "the columns header names no x, y and z");
    if (static_cast<int>(fields.size()) <= std::max({x, y, z}))
      throw Error(path, "line " + std::to_string(number) + ": too few fields");
    Vector3 p(finiteNumber(fields[x], path, number), finiteNumber(fields[y], path, number),
              finiteNumber(fields[z], path, number));
    const std::string name = label >= 0 && label < static_cast<int>(fields.size()) ? fields[label] : "";
    landmarks.push_back({name, system == CoordinateSystem::RAS ? flipXY(p) : p});
  }
  return landmarks;
}

// x, y, z (LPS mm), or 3D Slicer's markups table: l, p, s (LPS) or r, a, s
// (RAS), with `defined` 0 for a point not yet placed.
std::vector<Landmark> readCsv(const std::string& path, std::ifstream& in, CoordinateSystem& system) {
  std::string line;
  int number = 0;
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++number;
    if (number == 1) line = withoutByteOrderMark(line);
    if (const auto cr = line.find('\r'); cr != std::string::npos && cr + 1 < line.size())
      throw Error(path, "its lines end in a carriage return alone (old Mac text): save it with LF or CR LF line ends");
    // Comments come before the header; after it, a row's label may start with '#'.
    if (!holdsNothing(line, ",") && trimmed(line)[0] != '#') header = splitCsvFields(line, ',');
  }
  // Column names in any case: X, Label.
  for (std::string& name : header) name = lowerCase(name);
  const auto column = [&header](const char* name) { return columnIndex(header, name); };
  int x = column("x"), y = column("y"), z = column("z");
  const int label = column("label"), defined = column("defined");
  system = CoordinateSystem::LPS;
  if (x < 0 && y < 0 && z < 0) {
    if (column("l") >= 0 && column("p") >= 0 && column("s") >= 0) {
      x = column("l"), y = column("p"), z = column("s");
    } else if (column("r") >= 0 && column("a") >= 0 && column("s") >= 0) {
      x = column("r"), y = column("a"), z = column("s");
      system = CoordinateSystem::RAS;
    }
  }
  if (x < 0 || y < 0 || z < 0)
    throw Error(path,
                "the first line must name the columns x, y and z (LPS mm), or l, p, s or r, a, s as 3D Slicer's "
                "markups tables do");
  requireDistinctColumns(path, number, header);
  std::vector<Landmark> landmarks;
  while (std::getline(in, line)) {
    ++number;
    if (holdsNothing(line, ",")) continue;
    std::vector<std::string> fields = splitCsvFields(line, ',');
    // A separator that ends a row adds no value.
    while (fields.size() > header.size() && fields.back().empty()) fields.pop_back();
    // A row of more values than the header has columns is a point whose
    // values may have shifted (a stray comma, a decimal comma): which three
    // are x, y and z cannot be known.
    if (fields.size() > header.size())
      throw Error(path, "line " + std::to_string(number) + ": " + std::to_string(fields.size()) +
                            " fields, but the first line names " + std::to_string(header.size()) + " columns");
    if (static_cast<int>(fields.size()) <= std::max({x, y, z}))
      throw Error(path, "line " + std::to_string(number) + ": too few fields");
    // A point Slicer lists but has not placed: its position is not a click.
    if (defined >= 0 && defined < static_cast<int>(fields.size()) &&
        (fields[defined] == "0" || lowerCase(fields[defined]) == "false"))
      continue;
    const Vector3 p(finiteNumber(fields[x], path, number), finiteNumber(fields[y], path, number),
                    finiteNumber(fields[z], path, number));
    landmarks.push_back({label >= 0 && label < static_cast<int>(fields.size()) ? fields[label] : "",
                         system == CoordinateSystem::RAS ? flipXY(p) : p});
  }
  return landmarks;
}

std::string labelOf(const std::vector<Landmark>& landmarks, std::size_t i) {
  return landmarks[i].label.empty() ? "F-" + std::to_string(i + 1) : landmarks[i].label;
}

// A placed control point of a markups file, with 3D Slicer's defaults for
// the fields a point needs.
nlohmann::json markupsPoint(const std::string& id, const std::string& label, const Vector3& p) {
  return {{"id", id},
          {"label", label},
          {"description", ""},
          {"position", {p.x(), p.y(), p.z()}},
          {"orientation", {-1.0, -0.0, -0.0, -0.0, -1.0, -0.0, 0.0, 0.0, 1.0}},
          {"selected", true},
          {"locked", false},
          {"visibility", true},
          {"positionStatus", "defined"}};
}

// A control point's positionStatus and label as the reader takes them (it
// has checked them on placed points): "defined" when absent, and for a
// point without a label the name the reader gives it ("F-" and its number).
std::string statusOf(const nlohmann::json& point) {
  const auto at = point.find("positionStatus");
  return at != point.end() && at->is_string() ? at->get<std::string>() : "defined";
}
std::string readerLabel(const nlohmann::json& point, std::size_t index) {
  const auto at = point.find("label");
  return at != point.end() && at->is_string() ? at->get<std::string>() : "F-" + std::to_string(index + 1);
}

// The index in `markups` of the one point list or curve with placed points;
// else of the first with any control point, else of the first (as
// readLandmarkLists picks); -1 when there is none.
int editedMarkup(const std::string& path, const nlohmann::json& markups) {
  int first = -1, listed = -1, placed = -1, lists = 0;
  for (std::size_t m = 0; m < markups.size(); ++m) {
    const nlohmann::json& markup = markups[m];
    if (!onStructure(path, markup.value("type", std::string("Fiducial")))) continue;
    if (first < 0) first = static_cast<int>(m);
    const auto points = markup.find("controlPoints");
    if (points == markup.end() || points->empty()) continue;
    if (listed < 0) listed = static_cast<int>(m);
    if (std::none_of(points->begin(), points->end(),
                     [](const nlohmann::json& point) { return statusOf(point) == "defined"; }))
      continue;
    ++lists;
    placed = static_cast<int>(m);
  }
  if (lists > 1)
    throw Error(path, "holds " + std::to_string(lists) +
                          " lists of points; only a file with one list can take one list's edited points");
  return placed >= 0 ? placed : listed >= 0 ? listed : first;
}

// A label as a field of a .csv or .fcsv row: quoted when it holds a comma,
// so that the row keeps its columns (the readers take no quote inside a
// field: one becomes ').
std::string csvField(std::string label) {
  std::replace(label.begin(), label.end(), '"', '\'');
  return label.find(',') == std::string::npos ? label : '"' + label + '"';
}

}  // namespace

namespace {

// Every list of the file: a .mrk.json's markups, or the one list of a .fcsv
// or .csv.
std::vector<LandmarkList> readAllLists(const std::string& path) {
  const Format format = formatOf(path);
  std::ifstream in = openForReading(path);
  if (format == Format::MarkupsJson) return markupsLists(path, readMarkupsDocument(path, in));
  LandmarkList list;
  list.landmarks = format == Format::Fcsv ? readFcsv(path, in, list.stated) : readCsv(path, in, list.stated);
  return {list};
}

}  // namespace

std::vector<Landmark> readLandmarks(const std::string& path, CoordinateSystem* stated) {
  const std::vector<LandmarkList> lists = readAllLists(path);
  std::vector<Landmark> landmarks;
  for (const LandmarkList& list : lists)
    landmarks.insert(landmarks.end(), list.landmarks.begin(), list.landmarks.end());
  if (stated) *stated = lists.empty() ? CoordinateSystem::LPS : lists.front().stated;
  return landmarks;
}

std::vector<LandmarkList> readLandmarkLists(const std::string& path) {
  std::vector<LandmarkList> lists = readAllLists(path);
  const auto empty = [](const LandmarkList& list) { return list.landmarks.empty(); };
  if (lists.empty()) return {LandmarkList()};
  const auto filled = std::count_if(lists.begin(), lists.end(), [&](const LandmarkList& l) { return !empty(l); });
  if (filled == 0) return {lists.front()};
  // Beside two or more lists of points (several structures), a list without
  // points, skipped, would leave its structure out, and the lists after it
  // would take the wrong --name and --reference-label.
  const auto gap = std::find_if(lists.begin(), lists.end(), empty);
  if (filled > 1 && gap != lists.end())
    throw Error(path, "point list " + std::to_string(gap - lists.begin() + 1) +
                          (gap->name.empty() ? "" : " ('" + gap->name + "')") +
                          " holds no point, beside lists that do: place its structure's points, or delete the "
                          "empty list");
  lists.erase(std::remove_if(lists.begin(), lists.end(), empty), lists.end());
  return lists;
}

void writeLandmarks(const std::vector<Landmark>& landmarks, const std::string& path, CoordinateSystem system) {
  const Format format = formatOf(path);
  requireWritableDirectoryFor(path);
  for (const auto& landmark : landmarks)
    if (!landmark.position.allFinite()) throw Error(path, "landmark '" + landmark.label + "' is not finite");
  const bool ras = system == CoordinateSystem::RAS && format != Format::Csv;
  auto stored = [&](const Landmark& l) { return ras ? flipXY(l.position) : l.position; };

  AtomicOutput output(path);
  {
    std::ofstream out(output.temporaryPath());
    out.precision(17);
    if (format == Format::MarkupsJson) {
      nlohmann::json points = nlohmann::json::array();
      for (std::size_t i = 0; i < landmarks.size(); ++i)
        points.push_back(markupsPoint(std::to_string(i + 1), labelOf(landmarks, i), stored(landmarks[i])));
      nlohmann::json document = {
          {"@schema",
           "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/"
           "markups-schema-v1.0.3.json#"},
          {"markups",
           {{{"type", "Fiducial"},
             {"coordinateSystem", ras ? "RAS" : "LPS"},
             {"coordinateUnits", "mm"},
             {"controlPoints", points}}}}};
      out << document.dump(4) << '\n';
    } else if (format == Format::Fcsv) {
      out << "# Markups fiducial file version = 4.13\n# CoordinateSystem = " << (ras ? "RAS" : "LPS")
          << "\n# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n";
      for (std::size_t i = 0; i < landmarks.size(); ++i) {
        const Vector3 p = stored(landmarks[i]);
        out << i + 1 << ',' << p.x() << ',' << p.y() << ',' << p.z() << ",0,0,0,1,1,1,0,"
            << csvField(labelOf(landmarks, i)) << ",,\n";
      }
    } else {
      out << "x,y,z,label\n";
      for (std::size_t i = 0; i < landmarks.size(); ++i) {
        const Vector3 p = stored(landmarks[i]);
        out << p.x() << ',' << p.y() << ',' << p.z() << ',' << csvField(labelOf(landmarks, i)) << '\n';
      }
    }
    out.close();
    if (!out) throw writeFailure(path);
  }
  output.commit();
}

void updateLandmarks(const std::vector<Landmark>& landmarks, const std::string& path) {
  if (!std::filesystem::exists(path)) return writeLandmarks(landmarks, path);
  const Format format = formatOf(path);
  if (format != Format::MarkupsJson) {
    CoordinateSystem stated = CoordinateSystem::LPS;
    readLandmarks(path, &stated);
    return writeLandmarks(landmarks, path, stated);
  }
  std::ifstream in = openForReading(path);
  nlohmann::json document = readMarkupsDocument(path, in);
  in.close();
  markupsLists(path, document);  // the reader's checks: a file it refuses is not rewritten
  nlohmann::json& markups = document["markups"];
  const int edited = editedMarkup(path, markups);
  if (edited < 0) return writeLandmarks(landmarks, path);
  nlohmann::json& markup = markups[static_cast<std::size_t>(edited)];
  const bool ras = markup.value("coordinateSystem", std::string("LPS")) == "RAS";
  const nlohmann::json before = markup.value("controlPoints", nlohmann::json::array());

  // A point whose label is kept keeps its id, description and flags; the
  // names Slicer lists but has not placed (or is placing) stay, after the
  // placed points.
  std::vector<bool> taken(before.size(), false);
  std::vector<std::string> ids;
  for (const nlohmann::json& point : before)
    if (point.contains("id"))
      ids.push_back(point["id"].is_string() ? point["id"].get<std::string>() : point["id"].dump());
  nlohmann::json points = nlohmann::json::array();
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    if (!landmarks[i].position.allFinite()) throw Error(path, "landmark '" + landmarks[i].label + "' is not finite");
    const std::string label = labelOf(landmarks, i);
    const Vector3 p = ras ? flipXY(landmarks[i].position) : landmarks[i].position;
    std::size_t match = 0;
    while (match < before.size() &&
           (taken[match] || statusOf(before[match]) != "defined" || readerLabel(before[match], match) != label))
      ++match;
    if (match < before.size()) {
      taken[match] = true;
      nlohmann::json point = before[match];
      point["position"] = {p.x(), p.y(), p.z()};
      points.push_back(point);
      continue;
    }
    std::size_t number = ids.size() + 1;
    while (std::find(ids.begin(), ids.end(), std::to_string(number)) != ids.end()) ++number;
    ids.push_back(std::to_string(number));
    points.push_back(markupsPoint(ids.back(), label, p));
  }
  for (const nlohmann::json& point : before)
    if (statusOf(point) != "defined") points.push_back(point);
  markup["controlPoints"] = points;

  requireWritableDirectoryFor(path);
  AtomicOutput output(path);
  {
    std::ofstream out(output.temporaryPath());
    out << document.dump(4) << '\n';
    out.close();
    if (!out) throw writeFailure(path);
  }
  output.commit();
}

MatrixX3 landmarkPositions(const std::vector<Landmark>& landmarks) {
  MatrixX3 points(landmarks.size(), 3);
  for (std::size_t i = 0; i < landmarks.size(); ++i) points.row(i) = landmarks[i].position.transpose();
  return points;
}

}  // namespace dynsub
