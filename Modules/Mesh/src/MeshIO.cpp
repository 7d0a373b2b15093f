#include "dynsub/MeshIO.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub {

namespace {

MatrixX3 toMatrix(const std::vector<Vector3>& points) {
  MatrixX3 result(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) result.row(i) = points[i].transpose();
  return result;
}

// Parses one number of a text record; throws naming the file and line.
double parseNumber(const std::string& token, const std::string& path, int line) {
  try {
    size_t used = 0;
    const double value = std::stod(token, &used);
    if (used != token.size()) throw std::invalid_argument(token);
    return value;
  } catch (const std::exception&) {
    throw Error(path, "line " + std::to_string(line) + ": '" + token + "' is not a number");
  }
}

long parseInteger(const std::string& token, const std::string& path, int line) {
  try {
    size_t used = 0;
    const long value = std::stol(token, &used);
    if (used != token.size()) throw std::invalid_argument(token);
    return value;
  } catch (const std::exception&) {
    throw Error(path, "line " + std::to_string(line) + ": '" + token + "' is not an integer");
  }
}

// The rest of a "t" record: only "crease 2/1/0 a b sharpness" is DynSub's to read.
Crease parseCreaseTag(std::istringstream& record, const std::string& path, int line) {
  const std::string at = "line " + std::to_string(line) + ": ";
  std::string name, counts, a, b, sharpness, extra;
  record >> name >> counts;
  if (name != "crease") {
    throw Error(path, at + "the tag '" + name + "' is not supported (DynSub reads 't crease' tags only)");
  }
  if (counts != "2/1/0" || !(record >> a >> b >> sharpness) || (record >> extra)) {
    throw Error(path, at + "a crease tag must read 't crease 2/1/0 a b sharpness'");
  }
  const long first = parseInteger(a, path, line), second = parseInteger(b, path, line);
  if (first < 0 || second < 0 || first > std::numeric_limits<int>::max() || second > std::numeric_limits<int>::max()) {
    throw Error(path, at + "crease vertex indices are numbered from 0 and cannot be negative");
  }
  return Crease{static_cast<int>(first), static_cast<int>(second), parseNumber(sharpness, path, line)};
}

PolygonData readObj(const std::string& path) {
  std::ifstream in = openForReading(path, std::ios::binary);
  std::vector<Vector3> points;
  PolygonData data;
  data.firstNumber = 1;
  std::vector<int> faceLines;  // each face's line, to name an index past the last vertex
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    std::istringstream record(text);
    std::string keyword;
    if (!(record >> keyword)) continue;
    if (keyword == "v") {
      std::string x, y, z;
      if (!(record >> x >> y >> z)) {
        throw Error(path, "line " + std::to_string(line) + ": a vertex needs x y z");
      }
      points.emplace_back(parseNumber(x, path, line), parseNumber(y, path, line),
                          parseNumber(z, path, line));
    } else if (keyword == "f") {
      Polygon face;
      std::string corner;
      while (record >> corner) {
        // "v", "v/vt", "v//vn" or "v/vt/vn": only the vertex index matters here.
        const long index = parseInteger(corner.substr(0, corner.find('/')), path, line);
        // OBJ indices start at 1; negative ones count back from the last vertex read.
        const long resolved = index > 0 ? index - 1 : static_cast<long>(points.size()) + index;
        if (index == 0 || resolved < 0 || resolved > std::numeric_limits<int>::max()) {
          throw Error(path, "line " + std::to_string(line) + ": vertex index " +
                                std::to_string(index) + " is out of range");
        }
        face.push_back(static_cast<int>(resolved));
      }
      data.faces.push_back(std::move(face));
      faceLines.push_back(line);
    } else if (keyword == "t") {
      data.creases.push_back(parseCreaseTag(record, path, line));
    }
  }
  // Named here with its line, which the mesh check does not know.
  for (std::size_t f = 0; f < data.faces.size(); ++f)
    for (const int v : data.faces[f])
      if (v >= static_cast<int>(points.size()))
        throw Error(path, "line " + std::to_string(faceLines[f]) + ": vertex index " + std::to_string(v + 1) +
                              " is out of range (the file has " + std::to_string(points.size()) + " vertices)");
  data.points = toMatrix(points);
  return data;
}

// The next non-empty, non-comment line of an OFF file as tokens; empty at the
// end of the file.
std::vector<std::string> readOffRecord(std::istream& in, int& line) {
  std::string text;
  while (std::getline(in, text)) {
    ++line;
    text = text.substr(0, text.find('#'));
    std::istringstream record(text);
    std::vector<std::string> tokens;
    for (std::string token; record >> token;) tokens.push_back(token);
    if (!tokens.empty()) return tokens;
  }
  return {};
}

// As readOffRecord, where the file must go on.
std::vector<std::string> nextOffRecord(std::istream& in, const std::string& path, int& line, const char* expected) {
  std::vector<std::string> tokens = readOffRecord(in, line);
  if (tokens.empty()) throw Error(path, std::string("the file ends before ") + expected + " (truncated?)");
  return tokens;
}

PolygonData readOff(const std::string& path) {
  std::ifstream in = openForReading(path, std::ios::binary);
  int line = 0;
  std::vector<std::string> tokens = nextOffRecord(in, path, line, "the OFF header");
  // COFF, NOFF, STOFF, ...: per-vertex colours, normals or texture
  // coordinates follow x y z, and are not read.
  static const std::regex keyword("(ST)?C?N?OFF");
  if (!std::regex_match(tokens[0], keyword))
    throw Error(path, "line 1: expected the keyword OFF (or COFF, NOFF, STOFF, ...: 3D vertices), found '" +
                          tokens[0] + "'");
  tokens.erase(tokens.begin());
  if (tokens.empty()) tokens = nextOffRecord(in, path, line, "the vertex and face counts");
  if (tokens.size() < 2) throw Error(path, "line " + std::to_string(line) + ": expected vertex and face counts");
  const long vertexCount = parseInteger(tokens[0], path, line);
  const long faceCount = parseInteger(tokens[1], path, line);
  if (vertexCount < 0 || faceCount < 0) throw Error(path, "line " + std::to_string(line) + ": negative counts");
  // Every vertex and face takes at least two bytes: counts beyond the file's
  // size are a corrupt header, refused before anything is allocated.
  if (static_cast<std::uintmax_t>(vertexCount) + static_cast<std::uintmax_t>(faceCount) >
      std::filesystem::file_size(path))
    throw Error(path, "line " + std::to_string(line) + ": the counts announce more vertices and faces than the file holds");
  PolygonData data;
  data.points.resize(vertexCount, 3);
  for (long v = 0; v < vertexCount; ++v) {
    tokens = nextOffRecord(in, path, line, "all vertices are read");
    if (tokens.size() < 3) throw Error(path, "line " + std::to_string(line) + ": a vertex needs x y z");
    for (int c = 0; c < 3; ++c) data.points(v, c) = parseNumber(tokens[c], path, line);
  }
  for (long f = 0; f < faceCount; ++f) {
    tokens = nextOffRecord(in, path, line, "all faces are read");
    const long n = parseInteger(tokens[0], path, line);
    if (n < 0 || static_cast<long>(tokens.size()) < n + 1) {
      throw Error(path, "line " + std::to_string(line) + ": the face lists fewer vertices than it declares");
    }
    Polygon face;
    for (long k = 0; k < n; ++k) {
      const long index = parseInteger(tokens[k + 1], path, line);
      if (index < 0 || index > std::numeric_limits<int>::max())
        throw Error(path, "line " + std::to_string(line) + ": vertex index " + tokens[k + 1] + " is out of range");
      face.push_back(static_cast<int>(index));
    }
    data.faces.push_back(std::move(face));
  }
  // A record past the announced faces means the counts are wrong, and what
  // they leave out would be lost silently.
  if (!readOffRecord(in, line).empty())
    throw Error(path, "line " + std::to_string(line) + ": more records than the " + std::to_string(vertexCount) +
                          " vertices and " + std::to_string(faceCount) + " faces the header announces");
  return data;
}

// ---- PLY ----

struct PlyProperty {
  std::string name;
  std::string type;       // scalar type, or the item type of a list
  std::string countType;  // non-empty for lists
};

struct PlyElement {
  std::string name;
  long count = 0;
  std::vector<PlyProperty> properties;
};

int plyTypeSize(const std::string& type, const std::string& path) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  throw Error(path, "unknown PLY property type '" + type + "'");
}

class PlyValueReader {
 public:
  PlyValueReader(std::istream& in, const std::string& format, const std::string& path)
      : in_(in), path_(path), ascii_(format == "ascii"),
        swap_(format == "binary_big_endian") {}

  double read(const std::string& type) {
    if (ascii_) {
      std::string token;
      if (!(in_ >> token)) throw Error(path_, "the file ends before all PLY elements are read (truncated?)");
      try {
        return std::stod(token);
      } catch (const std::exception&) {
        throw Error(path_, "'" + token + "' is not a number");
      }
    }
    const int size = plyTypeSize(type, path_);
    unsigned char bytes[8];
    if (!in_.read(reinterpret_cast<char*>(bytes), size)) {
      throw Error(path_, "the file ends before all PLY elements are read (truncated?)");
    }
    if (swap_) std::reverse(bytes, bytes + size);
    auto as = [&bytes](auto value) {
      std::memcpy(&value, bytes, sizeof(value));
      return static_cast<double>(value);
    };
    if (type == "char" || type == "int8") return as(std::int8_t{});
    if (type == "uchar" || type == "uint8") return as(std::uint8_t{});
    if (type == "short" || type == "int16") return as(std::int16_t{});
    if (type == "ushort" || type == "uint16") return as(std::uint16_t{});
    if (type == "int" || type == "int32") return as(std::int32_t{});
    if (type == "uint" || type == "uint32") return as(std::uint32_t{});
    if (type == "float" || type == "float32") return as(float{});
    return as(double{});
  }

  // A list length or a vertex index: a whole number in [0, limit]. A float
  // beyond the range of int is refused before it is converted.
  long readIndex(const std::string& type, long limit, const char* what) {
    const double value = read(type);
    if (!(value >= 0 && value <= static_cast<double>(limit)) || value != std::floor(value))
      throw Error(path_, std::string("PLY ") + what + " " + formatNumber(value) + " is not a whole number from 0 to " +
                             std::to_string(limit));
    return static_cast<long>(value);
  }

 private:
  static std::string formatNumber(double value) {
    std::ostringstream text;
    text << value;
    return text.str();
  }

  std::istream& in_;
  std::string path_;
  bool ascii_;
  bool swap_;
};

// "8 vertex, 6 face": the header's counts, for errors.
std::string elementCounts(const std::vector<PlyElement>& elements) {
  std::string counts;
  for (const PlyElement& element : elements)
    counts += (counts.empty() ? "" : ", ") + std::to_string(element.count) + " " + element.name;
  return counts;
}

PolygonData readPly(const std::string& path) {
  std::ifstream in = openForReading(path, std::ios::binary);
  std::string text;
  if (!std::getline(in, text) || text.substr(0, 3) != "ply") throw Error(path, "not a PLY file (no 'ply' magic line)");
  std::string format;
  std::vector<PlyElement> elements;
  bool headerEnded = false;
  while (std::getline(in, text)) {
    if (!text.empty() && text.back() == '\r') text.pop_back();
    std::istringstream record(text);
    std::string keyword;
    record >> keyword;
    if (keyword == "format") {
      record >> format;
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian") {
        throw Error(path, "unknown PLY format '" + format + "'");
      }
    } else if (keyword == "element") {
      PlyElement element;
      record >> element.name >> element.count;
      if (!record || element.count < 0) throw Error(path, "malformed PLY element line '" + text + "'");
      // Every element takes at least one byte: a count beyond the file's
      // size is a corrupt header, refused before anything is allocated.
      if (static_cast<std::uintmax_t>(element.count) > std::filesystem::file_size(path))
        throw Error(path, "the PLY header announces " + std::to_string(element.count) + " " + element.name +
                              " elements, more than the file's size in bytes");
      elements.push_back(element);
    } else if (keyword == "property") {
      if (elements.empty()) throw Error(path, "PLY property before any element");
      PlyProperty property;
      std::string type;
      record >> type;
      if (type == "list") record >> property.countType >> property.type >> property.name;
      else {
        property.type = type;
        record >> property.name;
      }
      if (!record) throw Error(path, "malformed PLY property line '" + text + "'");
      elements.back().properties.push_back(property);
    } else if (keyword == "end_header") {
      headerEnded = true;
      break;
    }
  }
  if (!headerEnded) throw Error(path, "the PLY header has no end_header line");
  if (format.empty()) throw Error(path, "the PLY header has no format line");

  PolygonData data;
  PlyValueReader reader(in, format, path);
  bool sawVertices = false;
  for (const PlyElement& element : elements) {
    if (element.name == "vertex") {
      sawVertices = true;
      data.points.resize(element.count, 3);
      int axes[3] = {-1, -1, -1};
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const std::string& name = element.properties[p].name;
        if (name == "x") axes[0] = static_cast<int>(p);
        if (name == "y") axes[1] = static_cast<int>(p);
        if (name == "z") axes[2] = static_cast<int>(p);
      }
      if (axes[0] < 0 || axes[1] < 0 || axes[2] < 0) throw Error(path, "the PLY vertices have no x, y, z properties");
      for (long v = 0; v < element.count; ++v) {
        for (size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty& property = element.properties[p];
          if (!property.countType.empty()) {
            const long n = reader.readIndex(property.countType, std::numeric_limits<int>::max(), "list length");
            for (long k = 0; k < n; ++k) reader.read(property.type);
            continue;
          }
          const double value = reader.read(property.type);
          for (int c = 0; c < 3; ++c) {
            if (axes[c] == static_cast<int>(p)) data.points(v, c) = value;
          }
        }
      }
    } else {
      const bool isFace = element.name == "face";
      for (long i = 0; i < element.count; ++i) {
        for (const PlyProperty& property : element.properties) {
          const bool indices = isFace && (property.name == "vertex_indices" || property.name == "vertex_index");
          if (property.countType.empty()) {
            reader.read(property.type);
            continue;
          }
          const long n = reader.readIndex(property.countType, std::numeric_limits<int>::max(), "list length");
          Polygon face;
          for (long k = 0; k < n; ++k) {
            if (indices) face.push_back(static_cast<int>(reader.readIndex(property.type, std::numeric_limits<int>::max(), "vertex index")));
            else reader.read(property.type);
          }
          if (indices) data.faces.push_back(std::move(face));
        }
      }
    }
  }
  if (!sawVertices) throw Error(path, "the PLY file has no vertex element");
  // Records past the header's counts (a face more than announced) would be
  // dropped without a word, as in the OFF reader; a final newline is not one.
  for (char c; in.get(c);)
    if (!std::isspace(static_cast<unsigned char>(c)))
      throw Error(path, "the file goes on after the elements its PLY header announces (" + elementCounts(elements) +
                            "): a count in the header is wrong");
  return data;
}

}  // namespace

PolygonData readPolygonData(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  if (extension == ".obj") return readObj(path);
  if (extension == ".off") return readOff(path);
  if (extension == ".ply") return readPly(path);
  throw Error(path, "unknown mesh format '" + extension + "' (expected .obj, .off or .ply)");
}

ControlMesh readControlMesh(const std::string& path) {
  const PolygonData data = readPolygonData(path);
  ControlMesh mesh = ControlMesh::fromPolygons(data.points, data.faces, path, data.firstNumber);
  mesh.setCreases(data.creases, path);
  return mesh;
}

void writeObj(const ControlMesh& mesh, const std::string& path) {
  // OBJ is the one format written; under another name it would be read back as that format.
  if (lowerCaseExtension(path) != ".obj")
    throw UsageError(path, "the control mesh is written as OBJ: give the file the extension .obj");
  AtomicOutput output(path);
  {
    std::ofstream out(output.temporaryPath());
    if (!out) throw Error(path, "cannot open the file for writing");
    out.precision(17);  // round-trips every double
    out << "# DynSub control mesh: " << mesh.vertexCount() << " vertices, " << mesh.faceCount()
        << " faces\n";
    const MatrixX3 points = mesh.points();
    for (Eigen::Index v = 0; v < points.rows(); ++v) {
      out << "v " << points(v, 0) << ' ' << points(v, 1) << ' ' << points(v, 2) << '\n';
    }
    for (const Polygon& face : mesh.faces()) {
      out << 'f';
      for (int v : face) out << ' ' << v + 1;
      out << '\n';
    }
    for (const Crease& crease : mesh.creases()) {
      out << "t crease 2/1/0 " << crease.a << ' ' << crease.b << ' ' << crease.sharpness << '\n';
    }
    out.close();
    if (!out) throw writeFailure(path);
  }
  output.commit();
}

}  // namespace dynsub
