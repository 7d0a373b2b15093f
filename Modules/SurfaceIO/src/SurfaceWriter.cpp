#include "dynsub/SurfaceWriter.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>

#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/VtkXmlWriter.h"

namespace dynsub {

namespace {

// VTK XML polydata with the arrays SurfacePolyData.h's toPolyData makes, so
// that a file read back is the polydata the figures draw.
void writeVtp(const TriangleSurface& surface, const std::string& path, const std::string& name,
              const std::vector<PointScalars>& scalars, const std::string& space) {
  const vtkSmartPointer<vtkPolyData> data = toPolyData(surface);
  for (const PointScalars& s : scalars) {
    addPointData(data, s.name, s.values);
    if (s.far > 0.0) addFarDistance(data, s.name, s.far);
  }
  if (!space.empty()) {
    vtkNew<vtkStringArray> spaceName;
    spaceName->SetName("SPACE");
    spaceName->InsertNextValue(space);
    data->GetFieldData()->AddArray(spaceName);
  }
  writeVtkXml(data, path, name);
}

// Writes `bytes` to `path`, a new file; errors name `name`.
void writeFile(const std::string& path, const std::string& name, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw writeFailure(name);
}

// The shortest text that reads back as exactly `value`.
void appendNumber(std::string& text, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  text.append(buffer, result.ptr);
}

// Wavefront OBJ: vertices, their normals, and triangles that use both (1-based).
std::string objText(const TriangleSurface& surface) {
  std::string text = "# written by DynSub\n";
  for (const auto* rows : {&surface.points, &surface.normals}) {
    const char* tag = rows == &surface.points ? "v" : "vn";
    for (Eigen::Index i = 0; i < rows->rows(); ++i) {
      text += tag;
      for (int a = 0; a < 3; ++a) {
        text += ' ';
        appendNumber(text, (*rows)(i, a));
      }
      text += '\n';
    }
  }
  for (const auto& t : surface.triangles) {
    text += 'f';
    for (int p : t) text += ' ' + std::to_string(p + 1) + "//" + std::to_string(p + 1);
    text += '\n';
  }
  return text;
}

enum class ByteOrder { Little, Big };

// PLY and STL are little-endian, as memory is here; legacy VTK is big-endian.
template <typename T>
void appendBinary(std::string& bytes, T value, ByteOrder order = ByteOrder::Little) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "values are written from memory, little-endian");
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (order == ByteOrder::Big) std::reverse(raw, raw + sizeof(T));
  bytes.append(raw, sizeof(T));
}

// Binary little-endian PLY: float positions and normals (as VTK's PLY writer
// gives them), and each triangle as a list of three ints.
std::string plyBytes(const TriangleSurface& surface) {
  std::string bytes = "ply\nformat binary_little_endian 1.0\ncomment written by DynSub\nelement vertex " +
                      std::to_string(surface.points.rows()) +
                      "\nproperty float x\nproperty float y\nproperty float z\n"
                      "property float nx\nproperty float ny\nproperty float nz\nelement face " +
                      std::to_string(surface.triangles.size()) +
                      "\nproperty list uchar int vertex_indices\nend_header\n";
  for (Eigen::Index i = 0; i < surface.points.rows(); ++i) {
    for (int a = 0; a < 3; ++a) appendBinary(bytes, static_cast<float>(surface.points(i, a)));
    for (int a = 0; a < 3; ++a) appendBinary(bytes, static_cast<float>(surface.normals(i, a)));
  }
  for (const auto& t : surface.triangles) {
    appendBinary(bytes, static_cast<uint8_t>(3));
    for (int p : t) appendBinary(bytes, static_cast<int32_t>(p));
  }
  return bytes;
}

// Binary STL: an 80-byte header, the triangle count, then each triangle's
// unit normal (from its corners, as STL readers expect) and corners in floats.
std::string stlBytes(const TriangleSurface& surface, const std::string& path) {
  std::string bytes = "DynSub binary STL";
  bytes.resize(80, ' ');
  if (surface.triangles.size() > 0xffffffffu)
    throw Error(path, "more triangles than a binary STL file can count (4 294 967 295); nothing written");
  appendBinary(bytes, static_cast<uint32_t>(surface.triangles.size()));
  for (const auto& t : surface.triangles) {
    const Vector3 a = surface.points.row(t[0]).transpose(), b = surface.points.row(t[1]).transpose(),
                  c = surface.points.row(t[2]).transpose();
    Vector3 normal = (b - a).cross(c - a);
    const double length = normal.norm();
    normal = length > 0.0 ? Vector3(normal / length) : Vector3::Zero();
    for (int k = 0; k < 3; ++k) appendBinary(bytes, static_cast<float>(normal(k)));
    for (int p : t)
      for (int k = 0; k < 3; ++k) appendBinary(bytes, static_cast<float>(surface.points(p, k)));
    appendBinary(bytes, static_cast<uint16_t>(0));
  }
  return bytes;
}

// Legacy VTK polydata, binary (big-endian, as the format has it): float
// positions, triangles, and the normals and point data as point arrays.
// 3D Slicer reads the coordinate system from "SPACE=" in the title line.
std::string legacyVtkBytes(const TriangleSurface& surface, const std::vector<PointScalars>& scalars,
                           const std::string& space) {
  const auto n = surface.points.rows();
  const std::size_t triangles = surface.triangles.size();
  std::string bytes = "# vtk DataFile Version 4.2\nDynSub surface" + (space.empty() ? "" : " SPACE=" + space) +
                      "\nBINARY\nDATASET POLYDATA\nPOINTS " + std::to_string(n) + " float\n";
  for (Eigen::Index i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) appendBinary(bytes, static_cast<float>(surface.points(i, a)), ByteOrder::Big);
  bytes += "\nPOLYGONS " + std::to_string(triangles) + " " + std::to_string(4 * triangles) + "\n";
  for (const auto& t : surface.triangles) {
    appendBinary(bytes, static_cast<int32_t>(3), ByteOrder::Big);
    for (int p : t) appendBinary(bytes, static_cast<int32_t>(p), ByteOrder::Big);
  }
  bytes += "\nPOINT_DATA " + std::to_string(n) + "\nNORMALS Normals float\n";
  for (Eigen::Index i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) appendBinary(bytes, static_cast<float>(surface.normals(i, a)), ByteOrder::Big);
  for (const PointScalars& s : scalars) {
    bytes += "\nSCALARS " + s.name + " float 1\nLOOKUP_TABLE default\n";
    for (Eigen::Index i = 0; i < n; ++i) appendBinary(bytes, static_cast<float>(s.values[i]), ByteOrder::Big);
  }
  bytes += '\n';
  return bytes;
}

}  // namespace

std::vector<std::string> triangleSurfaceExtensions() { return {".vtp", ".vtk", ".obj", ".ply", ".stl"}; }

void requireTriangleSurfaceTarget(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  const std::vector<std::string> known = triangleSurfaceExtensions();
  if (std::find(known.begin(), known.end(), extension) == known.end()) {
    throw UsageError(path, "unknown surface format '" + extension + "' (expected .vtp, .vtk, .obj, .ply or .stl)");
  }
  requireWritableDirectoryFor(path);
}

void writeTriangleSurface(const TriangleSurface& surface, const std::string& path,
                          const std::vector<PointScalars>& scalars, const std::string& space) {
  requireTriangleSurfaceTarget(path);
  const std::string extension = lowerCaseExtension(path);
  if (!surface.points.allFinite()) throw Error(path, "the surface has non-finite coordinates; nothing written");
  for (const PointScalars& s : scalars) {
    if (s.values.size() != surface.points.rows() || !s.values.allFinite())
      throw Error(path, "point data '" + s.name + "' needs one finite value per point; nothing written");
    if (!(std::isfinite(s.far) && s.far >= 0.0))
      throw Error(path,
                  "point data '" + s.name + "' has a far distance that is not a finite number >= 0; nothing written");
  }
  if (!space.empty() && space != "LPS" && space != "RAS")
    throw Error(path, "unknown coordinate space '" + space + "' (expected LPS or RAS)");
  AtomicOutput output(path);
  if (extension == ".vtp") {
    writeVtp(surface, output.temporaryPath(), path, scalars, space);
  } else if (extension == ".vtk") {
    writeFile(output.temporaryPath(), path, legacyVtkBytes(surface, scalars, space));
  } else if (extension == ".obj") {
    writeFile(output.temporaryPath(), path, objText(surface));
  } else if (extension == ".ply") {
    writeFile(output.temporaryPath(), path, plyBytes(surface));
  } else {
    writeFile(output.temporaryPath(), path, stlBytes(surface, path));
  }
  output.commit();
}

void writePointCloudXyz(const MatrixX3& points, const std::string& path) {
  std::string text;
  for (Eigen::Index p = 0; p < points.rows(); ++p) {
    for (int c = 0; c < 3; ++c) {
      appendNumber(text, points(p, c));
      text += c < 2 ? ' ' : '\n';
    }
  }
  AtomicOutput output(path);
  writeFile(output.temporaryPath(), path, text);
  output.commit();
}

}  // namespace dynsub
