#include "dynsub/PointCloudIO.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iterator>
#include <optional>
#include <string>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include "dynsub/ControlMesh.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/MeshIO.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/TextFields.h"
#include "dynsub/VtkErrors.h"
#include "SlicerSpace.h"

namespace dynsub {

namespace {

// A line's fields: a CSV's between its separator (the first of ',', ';' and
// a tab that the line holds; an empty field counts, a separator inside
// double quotes does not split), else between runs of blanks. Trimmed of
// blanks and quotes; empty fields at the line's end (a separator ending it)
// dropped.
std::vector<std::string> fieldsOf(const std::string& line, bool csv) {
  std::vector<std::string> fields;
  char separator = 0;
  for (const char c : {',', ';', '\t'})
    if (!separator && line.find(c) != std::string::npos) separator = c;
  if (csv && separator) {
    fields = splitCsvFields(line, separator);
  } else {
    std::istringstream in(line);
    for (std::string field; in >> field;) fields.push_back(field);
  }
  for (std::string& f : fields) {
    const auto begin = f.find_first_not_of(" \t\r\""), end = f.find_last_not_of(" \t\r\"");
    f = begin == std::string::npos ? std::string() : f.substr(begin, end - begin + 1);
  }
  while (fields.size() > 1 && fields.back().empty()) fields.pop_back();
  return fields;
}

// Whether a column's name is the coordinate `axis` ('x', 'y' or 'z'): the
// letter in either case, alone or before a unit or a word ("x_mm", "X [mm]",
// "X Coordinate").
bool namesAxis(const std::string& name, char axis) {
  return !name.empty() && std::tolower(static_cast<unsigned char>(name[0])) == axis &&
         (name.size() == 1 || !std::isalnum(static_cast<unsigned char>(name[1])));
}

// The column of `names` that names `axis` (namesAxis), -1 when none; of
// several, the one named by the letter alone or in mm ("x" or "x_mm" beside
// "x_vox"), else an error.
int columnOf(const std::vector<std::string>& names, char axis, const std::function<Error(std::string)>& error) {
  std::vector<int> matches, preferred;
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (!namesAxis(names[c], axis)) continue;
    matches.push_back(static_cast<int>(c));
    const std::string lower = lowerCase(names[c]);
    if (lower.size() == 1 || lower.find("mm") != std::string::npos) preferred.push_back(static_cast<int>(c));
  }
  if (matches.size() == 1) return matches[0];
  if (matches.empty()) return -1;
  if (preferred.size() == 1) return preferred[0];
  throw error(std::string("the header names ") + std::to_string(matches.size()) + " columns " + axis +
              ", so which holds the coordinate cannot be told: name one x, y or z alone");
}

// The columns of x, y and z named by a CSV's first line (or, as 3D Slicer
// exports points, l, p and s: the same LPS axes), or nullopt for the first
// three when the line names three columns alone, none of them an axis. With
// more columns, or the axes named in part, which hold the coordinates cannot
// be told: an error; so are RAS columns (r, a, s), which would need x and y
// negated.
std::optional<std::array<std::size_t, 3>> namedColumns(std::vector<std::string> names, const std::string& path,
                                                       int line) {
  // CloudCompare writes "//" before the names.
  if (!names.empty() && names[0].rfind("//", 0) == 0) names[0].erase(0, 2);
  const std::function<Error(std::string)> error = [&](const std::string& what) {
    return Error(path, "line " + std::to_string(line) + ": " + what);
  };
  const auto columnsNamed = [&](const char* axes) {
    std::array<int, 3> columns{};
    for (int axis = 0; axis < 3; ++axis) columns[axis] = columnOf(names, axes[axis], error);
    return columns;
  };
  const auto count = [](const std::array<int, 3>& columns) {
    return std::count_if(columns.begin(), columns.end(), [](int c) { return c >= 0; });
  };
  const std::array<int, 3> xyz = columnsNamed("xyz");
  const std::array<int, 3> lps = count(xyz) == 0 ? columnsNamed("lps") : std::array<int, 3>{-1, -1, -1};
  const std::array<int, 3> named = count(xyz) > 0 ? xyz : lps;
  if (count(named) == 3)
    return std::array<std::size_t, 3>{static_cast<std::size_t>(named[0]), static_cast<std::size_t>(named[1]),
                                      static_cast<std::size_t>(named[2])};
  if (count(xyz) == 0 && count(columnsNamed("ras")) == 3)
    throw error(
        "the columns r, a and s are RAS coordinates, and DynSub reads LPS: negate r and a and name the "
        "columns x, y and z (or export the points in LPS)");
  if (count(named) > 0)
    throw error("the header does not name all the coordinates' columns x, y and z (" + std::to_string(names.size()) +
                " columns): name them so");
  if (names.size() == 3) return std::nullopt;
  throw error("the header names no columns x, y and z among its " + std::to_string(names.size()) +
              ", so which hold the coordinates cannot be told: name them so");
}

MatrixX3 readText(const std::string& path, bool csv) {
  std::ifstream in = openForReading(path);
  std::vector<Vector3> points;
  std::string line;
  int number = 0;
  bool header = csv;
  std::array<std::size_t, 3> columns{0, 1, 2};
  // The header's count of fields, else the first point's: a line of more
  // (a stray separator, a decimal comma) has values that may have shifted.
  std::size_t width = 0;
  std::string widthFrom = "the first point has ";
  while (std::getline(in, line)) {
    ++number;
    if (number == 1) line = withoutByteOrderMark(line);
    const size_t comment = line.find('#');
    if (comment != std::string::npos) line.erase(comment);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> fields = fieldsOf(line, csv);
    Vector3 p;
    bool numbers = true;
    for (int axis = 0; axis < 3 && numbers; ++axis)
      numbers = columns[axis] < fields.size() && parseNumber(fields[columns[axis]], p(axis));
    if (!numbers) {
      if (header) {  // a first line of column names
        header = false;
        if (const auto named = namedColumns(fields, path, number)) columns = *named;
        width = fields.size();
        widthFrom = "the header names ";
        continue;
      }
      throw Error(path, "line " + std::to_string(number) + ": expected three numbers x y z");
    }
    header = false;
    if (width == 0) width = fields.size();
    if (fields.size() > width)
      throw Error(path, "line " + std::to_string(number) + ": " + std::to_string(fields.size()) + " values, where " +
                            widthFrom + std::to_string(width));
    points.push_back(p);
  }
  if (points.empty()) throw Error(path, "has no points");
  MatrixX3 result(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) result.row(i) = points[i].transpose();
  return result;
}

// VTK's XML reader allocates what a piece's NumberOfPoints (and cells)
// announce before reading any data. A value no file of this size can hold
// (one byte per item, inflated at most 1032 times, zlib's limit) is a corrupt
// header: refused here rather than handed to the allocator.
void checkVtpCounts(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto appended = text.find("<AppendedData");
  if (appended != std::string::npos) text.resize(appended);  // the raw data holds arbitrary bytes
  const unsigned long long limit = 1032ULL * std::filesystem::file_size(path);
  for (auto at = text.find("NumberOf"); at != std::string::npos; at = text.find("NumberOf", at + 8)) {
    const auto quote = text.find('"', at);
    if (quote == std::string::npos || quote > at + 40 || text.compare(quote - 1, 1, "=") != 0) continue;
    const std::string name = text.substr(at, quote - 1 - at);
    errno = 0;
    const unsigned long long n = std::strtoull(text.c_str() + quote + 1, nullptr, 10);
    if (errno == ERANGE || n > limit)
      throw Error(path, "its header announces " + name + " " + text.substr(quote + 1, text.find('"', quote + 1) - quote - 1) +
                            ", more than a file of this size can hold");
  }
}

PointCloud readVtp(const std::string& path) {
  checkVtpCounts(path);
  vtkNew<vtkXMLPolyDataReader> reader;
  if (!reader->CanReadFile(path.c_str())) throw Error(path, "is not a VTK XML polydata file");
  reader->SetFileName(path.c_str());
  VtkErrors errors;
  errors.watch(reader);
  reader->Update();
  if (!errors.first().empty()) throw Error(path, "VTK could not read the points: " + errors.reason());
  if (reader->GetErrorCode() != 0) throw Error(path, "could not be read (truncated or corrupt?)");
  vtkPolyData* data = reader->GetOutput();
  if (!data || !data->GetPoints() || data->GetNumberOfPoints() == 0) throw Error(path, "has no points");
  PointCloud result;
  result.points = pointsOf(data);
  result.space = fieldSpace(data);
  result.meshVertices = data->GetNumberOfPolys() > 0 || data->GetNumberOfStrips() > 0;
  // Triangle strips are not unpacked into faces (the points are read all
  // the same); a file with strips gets no genus (closedMeshGenus).
  vtkCellArray* polys = data->GetPolys();
  vtkIdType count = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(count, ids);) {
    std::vector<int> face;
    for (vtkIdType k = 0; k < count; ++k) {
      if (ids[k] < 0 || ids[k] >= data->GetNumberOfPoints())
        throw Error(path, "a polygon names point " + std::to_string(ids[k]) + " of " +
                              std::to_string(data->GetNumberOfPoints()));
      face.push_back(static_cast<int>(ids[k]));
    }
    result.faces.push_back(std::move(face));
  }
  return result;
}

// The cloud as read, before a turn from RAS.
PointCloud readAsWritten(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  if (extension == ".xyz" || extension == ".txt" || extension == ".pwn") return {readText(path, false), false, {}, ""};
  if (extension == ".csv") return {readText(path, true), false, {}, ""};
  if (extension == ".vtp") return readVtp(path);
  if (extension == ".ply" || extension == ".off" || extension == ".obj") {
    PolygonData data = readPolygonData(path);
    if (data.points.rows() == 0) throw Error(path, "has no points");
    // The fit measures its coverage against the faces (SurfaceCoverage.h).
    for (const std::vector<int>& face : data.faces) {
      for (int v : face) {
        if (v < 0 || v >= data.points.rows())
          throw Error(path, "a polygon names point " + std::to_string(v) + " of " + std::to_string(data.points.rows()));
      }
    }
    const bool faces = !data.faces.empty();
    return {std::move(data.points), faces, std::move(data.faces), commentSpace(path)};
  }
  throw Error(path, "unknown point-cloud format '" + extension +
                        "' (expected .xyz, .txt, .pwn, .csv, .ply, .off, .obj or .vtp)");
}

}  // namespace

PointCloud readPointCloud(const std::string& path) {
  if (!std::filesystem::exists(path)) throw Error(path, "no such file");
  PointCloud cloud = readAsWritten(path);
  if (cloud.space == "RAS") {
    cloud.points.col(0) = -cloud.points.col(0);
    cloud.points.col(1) = -cloud.points.col(1);
  }
  return cloud;
}

int closedMeshGenus(const PointCloud& cloud, const std::string& source) {
  if (cloud.faces.empty()) return -1;
  // Points no face uses (common in exported files) are dropped, so that the
  // mesh check judges the surface alone.
  std::vector<int> index(static_cast<size_t>(cloud.points.rows()), -1);
  std::vector<Polygon> faces = cloud.faces;
  int used = 0;
  for (Polygon& face : faces) {
    for (int& v : face) {
      if (v < 0 || v >= cloud.points.rows()) return -1;
      if (index[v] < 0) index[v] = used++;
      v = index[v];
    }
  }
  MatrixX3 points(used, 3);
  for (Eigen::Index v = 0; v < cloud.points.rows(); ++v) {
    if (index[v] >= 0) points.row(index[v]) = cloud.points.row(v);
  }
  ControlMesh mesh;
  try {
    mesh = ControlMesh::fromPolygons(points, faces, source);
  } catch (const Error&) {
    return -1;  // not a mesh MeshCheck.h accepts: no genus to speak of
  }
  if (!mesh.isClosed() || mesh.pieceCount() != 1) return -1;
  return mesh.genus();
}

}  // namespace dynsub
