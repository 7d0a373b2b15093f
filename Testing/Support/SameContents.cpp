// Whether two output files hold the same contents, for checking that a change
// left a run's results alone when their encoding may have changed:
//   build/bin/SameContents FILE_A FILE_B
// PNG images are compared pixel by pixel (size, channels, every sample),
// VTK XML PolyData (.vtp) array by array (points, point, cell and field data,
// and every cell array), VTK XML unstructured grids (.vtu) likewise (with the
// cell types and each polyhedron's faces), NIfTI-1 files (.nii, .nii.gz, inflated) by their
// header's fields as numbers and their voxels byte by byte, any other file
// byte by byte. Exit code 0 when the same, 1 when not (what differs is
// printed), 2 when a file cannot be read.
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include <vtkAbstractArray.h>
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <zlib.h>

namespace {

std::string extensionOf(const std::string& path) {
  const auto dot = path.rfind('.');
  return dot == std::string::npos ? "" : path.substr(dot);
}

// Two arrays with the same name, type, shape and values (compared as
// doubles, bit for bit, so NaN equals NaN and -0 differs from 0).
bool sameArray(vtkAbstractArray* a, vtkAbstractArray* b, std::string& why) {
  if (!a || !b) {
    why = "an array is missing";
    return a == b;
  }
  const std::string name = a->GetName() ? a->GetName() : "(unnamed)";
  if ((a->GetName() ? std::string(a->GetName()) : "") != (b->GetName() ? std::string(b->GetName()) : "") ||
      a->GetDataType() != b->GetDataType() || a->GetNumberOfTuples() != b->GetNumberOfTuples() ||
      a->GetNumberOfComponents() != b->GetNumberOfComponents()) {
    why = "array " + name + ": name, type or shape differs";
    return false;
  }
  const vtkIdType count = a->GetNumberOfValues();
  auto* x = vtkDataArray::SafeDownCast(a);
  auto* y = vtkDataArray::SafeDownCast(b);
  for (vtkIdType i = 0; i < count; ++i) {
    bool same = true;
    if (x && y) {
      const double u = x->GetComponent(i / x->GetNumberOfComponents(), i % x->GetNumberOfComponents());
      const double v = y->GetComponent(i / y->GetNumberOfComponents(), i % y->GetNumberOfComponents());
      same = std::memcmp(&u, &v, sizeof u) == 0;
    } else {
      same = a->GetVariantValue(i) == b->GetVariantValue(i);
    }
    if (!same) {
      why = "array " + name + ": value " + std::to_string(i) + " differs";
      return false;
    }
  }
  return true;
}

bool sameFieldData(vtkFieldData* a, vtkFieldData* b, const std::string& what, std::string& why) {
  if (a->GetNumberOfArrays() != b->GetNumberOfArrays()) {
    why = what + ": a different number of arrays";
    return false;
  }
  for (int i = 0; i < a->GetNumberOfArrays(); ++i)
    if (!sameArray(a->GetAbstractArray(i), b->GetAbstractArray(i), why)) {
      why = what + ", " + why;
      return false;
    }
  return true;
}

// A file the reader of its extension reports an error for (exit code 2).
struct Unreadable {
  std::string path;
};

// `path` read by a VTK reader of type Reader. Throws Unreadable when the
// reader reports an error: VTK's readers give an empty output then, which
// would compare equal to another empty one.
template <class Reader>
vtkSmartPointer<Reader> readWith(const std::string& path) {
  auto reader = vtkSmartPointer<Reader>::New();
  bool failed = false;
  vtkNew<vtkCallbackCommand> onError;
  onError->SetClientData(&failed);
  onError->SetCallback([](vtkObject*, unsigned long, void* flag, void*) { *static_cast<bool*>(flag) = true; });
  reader->AddObserver(vtkCommand::ErrorEvent, onError);
  reader->SetFileName(path.c_str());
  reader->Update();
  if (failed) throw Unreadable{path};
  return reader;
}

// The same points, and the same point, cell and field data.
bool samePointsAndData(vtkPointSet* x, vtkPointSet* y, std::string& why) {
  if (!x->GetPoints() || !y->GetPoints()) {
    why = "no points read";
    return !x->GetPoints() && !y->GetPoints();
  }
  return sameArray(x->GetPoints()->GetData(), y->GetPoints()->GetData(), why) &&
         sameFieldData(x->GetPointData(), y->GetPointData(), "point data", why) &&
         sameFieldData(x->GetCellData(), y->GetCellData(), "cell data", why) &&
         sameFieldData(x->GetFieldData(), y->GetFieldData(), "field data", why);
}

bool samePolyData(const std::string& pathA, const std::string& pathB, std::string& why) {
  const auto a = readWith<vtkXMLPolyDataReader>(pathA), b = readWith<vtkXMLPolyDataReader>(pathB);
  vtkPolyData* x = a->GetOutput();
  vtkPolyData* y = b->GetOutput();
  if (!samePointsAndData(x, y, why)) return false;
  vtkCellArray* cellsA[] = {x->GetVerts(), x->GetLines(), x->GetPolys(), x->GetStrips()};
  vtkCellArray* cellsB[] = {y->GetVerts(), y->GetLines(), y->GetPolys(), y->GetStrips()};
  const char* kinds[] = {"verts", "lines", "polys", "strips"};
  for (int k = 0; k < 4; ++k) {
    if (!sameArray(cellsA[k]->GetOffsetsArray(), cellsB[k]->GetOffsetsArray(), why) ||
        !sameArray(cellsA[k]->GetConnectivityArray(), cellsB[k]->GetConnectivityArray(), why)) {
      why = std::string(kinds[k]) + ": " + why;
      return false;
    }
  }
  return true;
}

bool sameGrid(const std::string& pathA, const std::string& pathB, std::string& why) {
  const auto a = readWith<vtkXMLUnstructuredGridReader>(pathA), b = readWith<vtkXMLUnstructuredGridReader>(pathB);
  vtkUnstructuredGrid* x = a->GetOutput();
  vtkUnstructuredGrid* y = b->GetOutput();
  if (!samePointsAndData(x, y, why) || !sameArray(x->GetCellTypesArray(), y->GetCellTypesArray(), why) ||
      !sameArray(x->GetCells()->GetOffsetsArray(), y->GetCells()->GetOffsetsArray(), why) ||
      !sameArray(x->GetCells()->GetConnectivityArray(), y->GetCells()->GetConnectivityArray(), why))
    return false;
  vtkNew<vtkIdList> facesA, facesB;
  for (vtkIdType c = 0; c < x->GetNumberOfCells(); ++c) {
    x->GetFaceStream(c, facesA);
    y->GetFaceStream(c, facesB);
    bool same = facesA->GetNumberOfIds() == facesB->GetNumberOfIds();
    for (vtkIdType k = 0; same && k < facesA->GetNumberOfIds(); ++k) same = facesA->GetId(k) == facesB->GetId(k);
    if (!same) {
      why = "cell " + std::to_string(c) + ": the faces differ";
      return false;
    }
  }
  return true;
}

bool sameImage(const std::string& pathA, const std::string& pathB, std::string& why) {
  const auto a = readWith<vtkPNGReader>(pathA), b = readWith<vtkPNGReader>(pathB);
  int sizeA[3], sizeB[3];
  a->GetOutput()->GetDimensions(sizeA);
  b->GetOutput()->GetDimensions(sizeB);
  if (sizeA[0] != sizeB[0] || sizeA[1] != sizeB[1]) {
    why = "the images' sizes differ";
    return false;
  }
  return sameArray(a->GetOutput()->GetPointData()->GetScalars(), b->GetOutput()->GetPointData()->GetScalars(), why);
}

// A NIfTI file's bytes, inflated when gzipped (zlib reads plain files as they are).
std::string niftiBytes(const std::string& path) {
  gzFile file = gzopen(path.c_str(), "rb");
  if (!file) throw Unreadable{path};
  std::string bytes;
  char buffer[1 << 16];
  int got = 0;
  while ((got = gzread(file, buffer, sizeof buffer)) > 0) bytes.append(buffer, static_cast<std::size_t>(got));
  const bool failed = got < 0;
  gzclose(file);
  if (failed || bytes.size() < 352 || bytes.compare(344, 3, "n+1") != 0) throw Unreadable{path};
  return bytes;
}

// Two NIfTI-1 files: the header's float fields (pixdim, vox_offset, scaling,
// quaternion, offsets, affine rows) equal as numbers, so that 0 equals -0 (a
// writer may give either); every other byte, voxels included, the same.
bool sameNifti(const std::string& pathA, const std::string& pathB, std::string& why) {
  const std::string a = niftiBytes(pathA), b = niftiBytes(pathB);
  if (a.size() != b.size()) {
    why = "the inflated sizes differ";
    return false;
  }
  auto isFloatField = [](std::size_t at) { return (at >= 76 && at < 120) || (at >= 256 && at < 328); };
  for (std::size_t at = 0; at < 352; at += isFloatField(at) ? 4 : 1) {
    if (isFloatField(at)) {
      float x, y;
      std::memcpy(&x, a.data() + at, 4);
      std::memcpy(&y, b.data() + at, 4);
      if (x == y || (x != x && y != y)) continue;
    } else if (a[at] == b[at]) {
      continue;
    }
    why = "the header differs at byte " + std::to_string(at);
    return false;
  }
  why = "the voxels differ";
  return a.compare(352, std::string::npos, b, 352, std::string::npos) == 0;
}

bool sameBytes(const std::string& pathA, const std::string& pathB, std::string& why) {
  std::ifstream a(pathA, std::ios::binary), b(pathB, std::ios::binary);
  why = "the bytes differ";
  return std::string(std::istreambuf_iterator<char>(a), {}) == std::string(std::istreambuf_iterator<char>(b), {});
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: SameContents FILE_A FILE_B\n");
    return 2;
  }
  const std::string pathA = argv[1], pathB = argv[2];
  for (const std::string& path : {pathA, pathB})
    if (!std::ifstream(path)) {
      std::fprintf(stderr, "SameContents: %s: cannot be read\n", path.c_str());
      return 2;
    }
  const std::string extension = extensionOf(pathA);
  std::string why;
  bool same = false;
  try {
    if (extension != extensionOf(pathB)) {
      why = "the files' extensions differ";
    } else if (extension == ".png") {
      same = sameImage(pathA, pathB, why);
    } else if (extension == ".vtp") {
      same = samePolyData(pathA, pathB, why);
    } else if (extension == ".vtu") {
      same = sameGrid(pathA, pathB, why);
    } else if (extension == ".nii" || (pathA.size() > 7 && pathA.compare(pathA.size() - 7, 7, ".nii.gz") == 0)) {
      same = sameNifti(pathA, pathB, why);
    } else {
      same = sameBytes(pathA, pathB, why);
    }
  } catch (const Unreadable& e) {
    std::fprintf(stderr, "SameContents: %s: not a readable %s file\n", e.path.c_str(), extension.c_str());
    return 2;
  }
  if (!same) std::printf("%s and %s differ: %s\n", pathA.c_str(), pathB.c_str(), why.c_str());
  return same ? 0 : 1;
}
