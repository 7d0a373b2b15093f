#pragma once
// VTK's XML data files (.vtp polydata, .vtu unstructured grids), written by
// DynSub itself in the form VTK's own writer gives them: appended raw binary,
// little-endian, UInt32 block headers, LZ4 blocks of 32 KiB
// (vtkLZ4DataCompressor). VTK 8.1 and later, ParaView 5.5 and later and 3D
// Slicer 4.10 and later read them.
// NB: linking VTK's XML writer loaded VTK's core and data-model libraries,
// and the codecs they bring, at every command's start: about 19 ms of a
// command that writes nothing (`perf stat` of a program that only links them,
// Documentation/Performance.md, twenty-fourth session). A file is a header
// of XML and the arrays' bytes, which this writes without them.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynsub::vtkxml {

// One DataArray: its values' bytes as VTK reads them, in VTK's type names.
struct DataArray {
  std::string name;
  std::string type;  // "Float64", "Int64", "Int32", "UInt8" or "String"
  int components = 1;
  std::string bytes;  // the values, little-endian; a String array's strings each ending in '\0'
  int64_t tuples = 0;  // for a String array, the number of strings
  // The values' range (the magnitudes' for several components), written as
  // RangeMin and RangeMax as VTK does for data arrays; cell topology arrays have none.
  bool hasRange = false;
  double rangeMin = 0.0, rangeMax = 0.0;
};

DataArray float64Array(const std::string& name, const std::vector<double>& values, int components = 1);
// A tuple per row of `rows` (x, y, z of a point; one value of a vector).
DataArray float64Array(const std::string& name, const Eigen::Ref<const Eigen::MatrixXd>& rows);
DataArray int64Array(const std::string& name, const std::vector<int64_t>& values, bool withRange = false);
DataArray int32Array(const std::string& name, const std::vector<int32_t>& values, bool withRange = false);
DataArray uint8Array(const std::string& name, const std::vector<uint8_t>& values, bool withRange = false);
DataArray stringArray(const std::string& name, const std::vector<std::string>& strings);

// A group of arrays inside the piece: "PointData", "CellData", "Points",
// "Polys", "Cells" and so on, with its own attributes (e.g. Normals="Normals").
struct Section {
  std::string tag;
  std::string attributes;  // written as given after the tag, e.g. ` Normals="Normals"`
  std::vector<DataArray> arrays;
};

// A file of one piece: `type` is "PolyData" or "UnstructuredGrid";
// `pieceAttributes` the piece's counts (` NumberOfPoints="8" NumberOfCells="1"`).
struct Dataset {
  std::string type;
  std::vector<DataArray> fieldData;
  std::string pieceAttributes;
  std::vector<Section> sections;
};

// Writes `data` to `path` (an AtomicOutput's temporary file, say). Throws
// dynsub::Error naming `name` (the file the user asked for) when the file
// cannot be opened or written (writeFailure: a full disk named as such).
void writeDataset(const Dataset& data, const std::string& path, const std::string& name);

}  // namespace dynsub::vtkxml
