#include "dynsub/SurfaceWriter.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <utility>

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

// A new file at `path` written through `bytes` a block at a time, so that
// a surface of a billion triangles is not held a second time as its file's
// text; errors name `name`.
class FileBlocks {
 public:
  FileBlocks(const std::string& path, std::string name) : out_(path, std::ios::binary), name_(std::move(name)) {}
  std::string bytes;
  // Passes `bytes` on to the file once they fill a block.
  void spill() {
    if (bytes.size() >= kBlock) write();
  }
  void close() {
    write();
    out_.close();
    if (!out_) throw writeFailure(name_);
  }

 private:
  static constexpr std::size_t kBlock = 1 << 20;
  void write() {
    out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    bytes.clear();
  }
  std::ofstream out_;
  std::string name_;
};

// The shortest text that reads back as exactly `value`.
void appendNumber(std::string& text, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  text.append(buffer, result.ptr);
}

// Wavefront OBJ: vertices, their normals, and triangles that use both (1-based).
void writeObjText(const TriangleSurface& surface, FileBlocks& file) {
  std::string& text = file.bytes;
  text = "# written by DynSub\n";
  for (const auto* rows : {&surface.points, &surface.normals}) {
    const char* tag = rows == &surface.points ? "v" : "vn";
    for (Eigen::Index i = 0; i < rows->rows(); ++i) {
      text += tag;
      for (int a = 0; a < 3; ++a) {
        text += ' ';
        appendNumber(text, (*rows)(i, a));
      }
      text += '\n';
      file.spill();
    }
  }
  for (const auto& t : surface.triangles) {
    text += 'f';
    for (int p : t) {
      const std::string index = std::to_string(p + 1);
      text += ' ' + index + "//" + index;
    }
    text += '\n';
    file.spill();
  }
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
void writePlyBytes(const TriangleSurface& surface, FileBlocks& file) {
  std::string& bytes = file.bytes;
  bytes = "ply\nformat binary_little_endian 1.0\ncomment written by DynSub\nelement vertex " +
          std::to_string(surface.points.rows()) +
          "\nproperty float x\nproperty float y\nproperty float z\n"
          "property float nx\nproperty float ny\nproperty float nz\nelement face " +
          std::to_string(surface.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (Eigen::Index i = 0; i < surface.points.rows(); ++i) {
    for (int a = 0; a < 3; ++a) appendBinary(bytes, static_cast<float>(surface.points(i, a)));
    for (int a = 0; a < 3; ++a) appendBinary(bytes, static_cast<float>(surface.normals(i, a)));
    file.spill();
  }
  for (const auto& t : surface.triangles) {
    appendBinary(bytes, static_cast<uint8_t>(3));
    for (int p : t) appendBinary(bytes, static_cast<int32_t>(p));
    file.spill();
  }
}

// Binary STL: an 80-byte header, the triangle count, then each triangle's
// unit normal (from its corners, as STL readers expect) and corners in floats.
void writeStlBytes(const TriangleSurface& surface, const std::string& path, FileBlocks& file) {
  std::string& bytes = file.bytes;
  bytes = "DynSub binary STL";
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
    file.spill();
  }
}

// Legacy VTK polydata, binary (big-endian, as the format has it): float
// positions, triangles, and the normals and point data as point arrays.
// 3D Slicer reads the coordinate system from "SPACE=" in the title line.
void writeLegacyVtkBytes(const TriangleSurface& surface, const std::vector<PointScalars>& scalars,
                         const std::string& space, FileBlocks& file) {
  const auto n = surface.points.rows();
  const std::size_t triangles = surface.triangles.size();
  std::string& bytes = file.bytes;
  bytes = "# vtk DataFile Version 4.2\nDynSub surface" + (space.empty() ? "" : " SPACE=" + space) +
          "\nBINARY\nDATASET POLYDATA\nPOINTS " + std::to_string(n) + " float\n";
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) appendBinary(bytes, static_cast<float>(surface.points(i, a)), ByteOrder::Big);
    file.spill();
  }
  bytes += "\nPOLYGONS " + std::to_string(triangles) + " " + std::to_string(4 * triangles) + "\n";
  for (const auto& t : surface.triangles) {
    appendBinary(bytes, static_cast<int32_t>(3), ByteOrder::Big);
    for (int p : t) appendBinary(bytes, static_cast<int32_t>(p), ByteOrder::Big);
    file.spill();
  }
  bytes += "\nPOINT_DATA " + std::to_string(n) + "\nNORMALS Normals float\n";
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) appendBinary(bytes, static_cast<float>(surface.normals(i, a)), ByteOrder::Big);
    file.spill();
  }
  for (const PointScalars& s : scalars) {
    bytes += "\nSCALARS " + s.name + " float 1\nLOOKUP_TABLE default\n";
    for (Eigen::Index i = 0; i < n; ++i) {
      appendBinary(bytes, static_cast<float>(s.values[i]), ByteOrder::Big);
      file.spill();
    }
  }
  bytes += '\n';
}

}  // namespace

std::uint64_t surfaceWriterBytes(const std::string& path, std::uint64_t points, std::uint64_t triangles) {
  if (lowerCaseExtension(path) != ".vtp") return 0;
  // toPolyData's arrays: positions and normals in doubles; 32-bit corners
  // and offsets, the element type and the element; and the XML writer's
  // blocks, about 10 bytes a triangle (measured by peak resident memory).
  return points * 6 * sizeof(double) + triangles * (4 * sizeof(std::int32_t) + 1 + sizeof(int) + 10);
}

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
  } else {
    FileBlocks file(output.temporaryPath(), path);
    if (extension == ".vtk") writeLegacyVtkBytes(surface, scalars, space, file);
    if (extension == ".obj") writeObjText(surface, file);
    if (extension == ".ply") writePlyBytes(surface, file);
    if (extension == ".stl") writeStlBytes(surface, path, file);
    file.close();
  }
  output.commit();
}

void writePointCloudXyz(const MatrixX3& points, const std::string& path) {
  AtomicOutput output(path);
  FileBlocks file(output.temporaryPath(), path);
  for (Eigen::Index p = 0; p < points.rows(); ++p) {
    for (int c = 0; c < 3; ++c) {
      appendNumber(file.bytes, points(p, c));
      file.bytes += c < 2 ? ' ' : '\n';
    }
    file.spill();
  }
  file.close();
  output.commit();
}

}  // namespace dynsub
