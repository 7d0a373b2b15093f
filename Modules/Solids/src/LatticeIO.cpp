#include "dynsub/LatticeIO.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <vtkCellData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/TextFields.h"
#include "dynsub/VtkXmlWriter.h"

namespace dynsub {

namespace {

// Lines without comments and blank lines, with their numbers.
class LatticeReader {
 public:
  explicit LatticeReader(const std::string& path) : path_(path), in_(openForReading(path)) {}

  std::istringstream next(const char* expecting) {
    std::string line;
    if (!nextDataLine(line)) throw Error(path_, "the file ends early: expected " + std::string(expecting));
    return std::istringstream(line);
  }

  // Refuses a line with data after the last item the counts announce: the
  // counts are then wrong, and what they leave out would be lost silently.
  void expectEnd(const std::string& last) {
    std::string line;
    if (nextDataLine(line)) fail("more data after " + last);
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw Error(path_, "line " + std::to_string(number_) + ": " + message);
  }

  int count(const char* keyword) {
    std::istringstream line = next(keyword);
    std::string word;
    long long n = -1;
    std::string extra;
    if (!(line >> word >> n) || word != keyword || n < 0 || n > 100000000 || line >> extra)
      fail(std::string("expected \"") + keyword + " N\"");
    // Each item is a line of at least two bytes: a count beyond that is a
    // corrupt file, refused before anything is allocated for it.
    std::error_code error;
    const auto size = std::filesystem::file_size(path_, error);
    if (!error && static_cast<unsigned long long>(n) > size / 2)
      fail(std::string("\"") + keyword + " " + std::to_string(n) + "\" announces more items than the file holds");
    return static_cast<int>(n);
  }

  std::vector<int> indexList(const char* what) {
    std::istringstream line = next(what);
    long long k = 0;
    if (!(line >> k) || k < 1 || k > 1000) fail(std::string("expected a ") + what + ": a count, then indices");
    std::vector<int> indices(k);
    for (int& i : indices) {
      long long v;
      if (!(line >> v) || v < 0 || v > 2000000000LL) fail(std::string("expected ") + std::to_string(k) + " indices");
      i = static_cast<int>(v);
    }
    std::string extra;
    if (line >> extra) fail("more indices than the count " + std::to_string(k));
    return indices;
  }

 private:
  // The next line that is neither blank nor a comment; false at the end of the file.
  bool nextDataLine(std::string& line) {
    while (std::getline(in_, line)) {
      ++number_;
      const auto first = line.find_first_not_of(" \t\r");
      if (first != std::string::npos && line[first] != '#') return true;
    }
    return false;
  }

  std::string path_;
  std::ifstream in_;
  int number_ = 0;
};

}  // namespace

Lattice readLattice(const std::string& path) {
  if (lowerCaseExtension(path) != ".lattice")
    throw Error(path, "unknown lattice format '" + lowerCaseExtension(path) + "' (expected .lattice)");
  LatticeReader reader(path);
  {
    std::istringstream header = reader.next("the header \"dynsub-lattice 1\"");
    std::string word;
    int version = 0;
    if (!(header >> word >> version) || word != "dynsub-lattice" || version != 1)
      reader.fail("expected the header \"dynsub-lattice 1\"");
  }
  const int n = reader.count("points");
  MatrixX3 points(n, 3);
  for (int i = 0; i < n; ++i) {
    // Word by word, so that a decimal comma ("0,5") or a stray character is
    // refused rather than read as the number before it.
    std::istringstream line = reader.next("a point");
    std::vector<std::string> words;
    for (std::string word; line >> word;) words.push_back(word);
    if (words.size() != 3) reader.fail("expected a point \"x y z\", got " + std::to_string(words.size()) + " values");
    for (int axis = 0; axis < 3; ++axis)
      if (!parseNumber(words[axis], points(i, axis)))
        reader.fail("'" + words[axis] + "' is not a number (a point is \"x y z\", with a decimal point)");
    if (!points.row(i).allFinite()) reader.fail("the point is not finite");
  }
  const int f = reader.count("faces");
  std::vector<std::vector<int>> faces(f);
  for (auto& face : faces) face = reader.indexList("face");
  const int c = reader.count("cells");
  std::vector<std::vector<int>> cells(c);
  for (auto& cell : cells) cell = reader.indexList("cell");
  reader.expectEnd("the " + std::to_string(c) + " cells the file announces");
  return Lattice::fromCells(std::move(points), std::move(faces), std::move(cells), path);
}

namespace {

void writeText(const Lattice& l, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw Error(path, "cannot write the file");
  out << "# DynSub control lattice: " << l.pointCount() << " points, " << l.edgeCount() << " edges, "
      << l.faceCount() << " faces, " << l.cellCount() << " cells\n"
      << "dynsub-lattice 1\npoints " << l.pointCount() << '\n'
      << std::setprecision(17);
  for (int i = 0; i < l.pointCount(); ++i)
    out << l.points()(i, 0) << ' ' << l.points()(i, 1) << ' ' << l.points()(i, 2) << '\n';
  out << "faces " << l.faceCount() << '\n';
  for (const auto& face : l.faces()) {
    out << face.size();
    for (int p : face) out << ' ' << p;
    out << '\n';
  }
  out << "cells " << l.cellCount() << '\n';
  for (const auto& cell : l.cells()) {
    out << cell.size();
    for (int f : cell) out << ' ' << f;
    out << '\n';
  }
  if (!out) throw Error(path, "writing the file failed");
}

// Every cell as a VTK_POLYHEDRON with its faces, and per cell the number of
// its faces on the lattice's boundary (cell data "BoundaryFaces").
void writeVtu(const Lattice& l, const std::string& path, const std::string& name) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(l.pointCount());
  for (int p = 0; p < l.pointCount(); ++p) points->SetPoint(p, l.points()(p, 0), l.points()(p, 1), l.points()(p, 2));
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(points);
  grid->Allocate(l.cellCount());
  vtkNew<vtkIntArray> boundaryFaces;
  boundaryFaces->SetName("BoundaryFaces");
  for (const std::vector<int>& cell : l.cells()) {
    std::vector<vtkIdType> corners, faces;
    int boundary = 0;
    for (int f : cell) {
      boundary += l.isBoundaryFace(f);
      faces.push_back(static_cast<vtkIdType>(l.faces()[f].size()));
      for (int p : l.faces()[f]) {
        faces.push_back(p);
        corners.push_back(p);
      }
    }
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    grid->InsertNextCell(VTK_POLYHEDRON, static_cast<vtkIdType>(corners.size()), corners.data(),
                         static_cast<vtkIdType>(cell.size()), faces.data());
    boundaryFaces->InsertNextValue(boundary);
  }
  grid->GetCellData()->AddArray(boundaryFaces);
  writeVtkXml(grid, path, name);
}

}  // namespace

void requireLatticeTarget(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  if (extension != ".lattice" && extension != ".vtu")
    throw UsageError(path, "unknown lattice format '" + extension + "' (expected .lattice or .vtu)");
  requireWritableDirectoryFor(path);
}

void writeLattice(const Lattice& lattice, const std::string& path) {
  requireLatticeTarget(path);
  const std::string extension = lowerCaseExtension(path);
  AtomicOutput output(path);
  if (extension == ".lattice") {
    writeText(lattice, output.temporaryPath());
  } else {
    writeVtu(lattice, output.temporaryPath(), path);
  }
  output.commit();
}

}  // namespace dynsub
