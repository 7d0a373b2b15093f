#include "dynsub/PointCloudIO.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include "dynsub/Error.h"
#include "dynsub/TextFields.h"
#include "dynsub/FileNames.h"
#include "dynsub/MeshIO.h"

namespace dynsub {

namespace {

// Parses the first three numbers of a line split at `separators`; false if
// the line has fewer than three fields or a field is not a number.
bool parseXyz(std::string line, const std::string& separators, Vector3& point) {
  for (char& c : line) {
    if (separators.find(c) != std::string::npos) c = ' ';
  }
  std::istringstream in(line);
  std::string field;
  for (int i = 0; i < 3; ++i) {
    if (!(in >> field) || !parseNumber(field, point(i))) return false;
  }
  return true;
}

Matrix3X readText(const std::string& path, bool csv) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot be opened");
  std::vector<Vector3> points;
  std::string line;
  int number = 0;
  bool header = csv;
  while (std::getline(in, line)) {
    ++number;
    const size_t comment = line.find('#');
    if (comment != std::string::npos) line.erase(comment);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    Vector3 p;
    if (!parseXyz(line, csv ? ",;\t\r" : " \t\r", p)) {
      if (header) {  // a first line of column names
        header = false;
        continue;
      }
      throw Error(path, "line " + std::to_string(number) + ": expected three numbers x y z");
    }
    header = false;
    points.push_back(p);
  }
  if (points.empty()) throw Error(path, "has no points");
  Matrix3X result(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) result.row(i) = points[i].transpose();
  return result;
}

Matrix3X readVtp(const std::string& path) {
  vtkNew<vtkXMLPolyDataReader> reader;
  if (!reader->CanReadFile(path.c_str())) throw Error(path, "is not a VTK XML polydata file");
  reader->SetFileName(path.c_str());
  reader->Update();
  if (reader->GetErrorCode() != 0) throw Error(path, "could not be read (truncated or corrupt?)");
  vtkPolyData* data = reader->GetOutput();
  if (!data || !data->GetPoints() || data->GetNumberOfPoints() == 0) throw Error(path, "has no points");
  Matrix3X result(data->GetNumberOfPoints(), 3);
  for (vtkIdType i = 0; i < data->GetNumberOfPoints(); ++i) {
    double p[3];
    data->GetPoint(i, p);
    result.row(i) << p[0], p[1], p[2];
  }
  return result;
}

}  // namespace

Matrix3X readPointCloud(const std::string& path) {
  if (!std::filesystem::exists(path)) throw Error(path, "no such file");
  const std::string extension = lowerCaseExtension(path);
  if (extension == ".xyz" || extension == ".txt") return readText(path, false);
  if (extension == ".csv") return readText(path, true);
  if (extension == ".vtp") return readVtp(path);
  if (extension == ".ply" || extension == ".off" || extension == ".obj") {
    Matrix3X points = readPolygonData(path).points;
    if (points.rows() == 0) throw Error(path, "has no points");
    return points;
  }
  throw Error(path, "unknown point-cloud format '" + extension +
                        "' (expected .xyz, .txt, .csv, .ply, .off, .obj or .vtp)");
}

}  // namespace dynsub
