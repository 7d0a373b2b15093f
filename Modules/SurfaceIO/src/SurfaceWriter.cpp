#include "dynsub/SurfaceWriter.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>
#include <fstream>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/VtkXmlWriter.h"

namespace dynsub {

namespace {

// The triangles' point ids and the end of each one's, as Id.
template <typename Id>
vtkxml::Section polys(const TriangleSurface& surface,
                      vtkxml::DataArray (*array)(const std::string&, const std::vector<Id>&, bool)) {
  const std::size_t triangles = surface.triangles.size();
  std::vector<Id> connectivity(3 * triangles), offsets(triangles);
  for (std::size_t t = 0; t < triangles; ++t) {
    std::copy(surface.triangles[t].begin(), surface.triangles[t].end(), connectivity.begin() + 3 * t);
    offsets[t] = static_cast<Id>(3 * (t + 1));
  }
  return {"Polys", "", {array("connectivity", connectivity, false), array("offsets", offsets, false)}};
}

// VTK XML polydata as VTK's XML writer gives it (VtkXmlWriter.h), with the
// arrays SurfacePolyData.h's toPolyData makes, so that a file read back is
// the polydata the figures draw.
void writeVtp(const TriangleSurface& surface, const std::string& path, const std::string& name,
              const std::vector<PointScalars>& scalars, const std::string& space) {
  const Eigen::Index n = surface.points.rows();
  const std::size_t triangles = surface.triangles.size();
  std::vector<uint8_t> type(triangles);
  std::vector<int32_t> element(triangles);
  for (std::size_t t = 0; t < triangles; ++t) {
    type[t] = static_cast<uint8_t>(surface.triangleType[t]);
    element[t] = surface.triangleElement[t];
  }
  vtkxml::Dataset data;
  data.type = "PolyData";
  if (!space.empty()) data.fieldData.push_back(vtkxml::stringArray("SPACE", {space}));
  data.pieceAttributes = " NumberOfPoints=\"" + std::to_string(n) +
                         "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
                         std::to_string(triangles) + "\"";
  vtkxml::Section pointData{"PointData", " Normals=\"Normals\"", {vtkxml::float64Array("Normals", surface.normals)}};
  for (const PointScalars& s : scalars) pointData.arrays.push_back(vtkxml::float64Array(s.name, s.values));
  data.sections.push_back(std::move(pointData));
  data.sections.push_back(
      {"CellData", "", {vtkxml::uint8Array("ElementType", type, true), vtkxml::int32Array("Element", element, true)}});
  data.sections.push_back({"Points", "", {vtkxml::float64Array("Points", surface.points)}});
  for (const char* empty : {"Verts", "Lines", "Strips"})
    data.sections.push_back({empty, "", {vtkxml::int64Array("connectivity", {}), vtkxml::int64Array("offsets", {})}});
  // NB: 32-bit point ids where they fit: the connectivity and offsets were
  // half of a fitted surface's bytes as 64-bit ids, all to be compressed and written.
  const bool small = n < (Eigen::Index{1} << 31) && 3 * triangles < (std::size_t{1} << 31);
  data.sections.push_back(small ? polys<int32_t>(surface, &vtkxml::int32Array)
                                : polys<int64_t>(surface, &vtkxml::int64Array));
  vtkxml::writeDataset(data, path, name);
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

template <typename T>
void appendBinary(std::string& bytes, T value) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "PLY and STL are written little-endian as in memory");
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
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

}  // namespace

std::vector<std::string> triangleSurfaceExtensions() { return {".vtp", ".obj", ".ply", ".stl"}; }

void writeTriangleSurface(const TriangleSurface& surface, const std::string& path,
                          const std::vector<PointScalars>& scalars, const std::string& space) {
  const std::string extension = lowerCaseExtension(path);
  const std::vector<std::string> known = triangleSurfaceExtensions();
  if (std::find(known.begin(), known.end(), extension) == known.end()) {
    throw Error(path, "unknown surface format '" + extension + "' (expected .vtp, .obj, .ply or .stl)");
  }
  if (!surface.points.allFinite()) throw Error(path, "the surface has non-finite coordinates; nothing written");
  for (const PointScalars& s : scalars)
    if (s.values.size() != surface.points.rows() || !s.values.allFinite())
      throw Error(path, "point data '" + s.name + "' needs one finite value per point; nothing written");
  if (!space.empty() && space != "LPS" && space != "RAS")
    throw Error(path, "unknown coordinate space '" + space + "' (expected LPS or RAS)");
  AtomicOutput output(path);
  if (extension == ".vtp") {
    writeVtp(surface, output.temporaryPath(), path, scalars, space);
  } else if (extension == ".obj") {
    writeFile(output.temporaryPath(), path, objText(surface));
  } else if (extension == ".ply") {
    writeFile(output.temporaryPath(), path, plyBytes(surface));
  } else {
    writeFile(output.temporaryPath(), path, stlBytes(surface, path));
  }
  output.commit();
}

}  // namespace dynsub
