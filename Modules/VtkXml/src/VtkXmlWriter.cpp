#include "dynsub/VtkXmlWriter.h"

#include <lz4.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <limits>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"

namespace dynsub::vtkxml {
namespace {

static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559, "VTK's Float64 is IEEE double");

// VTK's compressed arrays are cut into blocks of this many bytes (its default).
constexpr std::size_t kBlockSize = 32768;

template <typename T>
std::string bytesOf(const std::vector<T>& values) {
  // The bytes as they lie in memory: the header's byte_order is "LittleEndian".
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the files are written little-endian as in memory");
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

template <typename T>
DataArray integerArray(const std::string& name, const char* type, const std::vector<T>& values, bool withRange) {
  DataArray array{name, type, 1, bytesOf(values), static_cast<int64_t>(values.size())};
  if (withRange && !values.empty()) {
    const auto [low, high] = std::minmax_element(values.begin(), values.end());
    array.hasRange = true;
    array.rangeMin = static_cast<double>(*low);
    array.rangeMax = static_cast<double>(*high);
  }
  return array;
}

// The LZ4-compressed form of `bytes`: VTK's header (the block count, the
// block size, the last block's size when it is short, else 0, then each
// block's compressed size, all UInt32) followed by the blocks.
std::string compressed(const std::string& bytes, const std::string& name) {
  const std::size_t blocks = (bytes.size() + kBlockSize - 1) / kBlockSize;
  if (blocks > std::numeric_limits<uint32_t>::max()) throw Error(name, "an array is too large for a VTK XML file");
  std::vector<uint32_t> header(3 + blocks);
  header[0] = static_cast<uint32_t>(blocks);
  header[1] = static_cast<uint32_t>(kBlockSize);
  header[2] = static_cast<uint32_t>(bytes.size() % kBlockSize);
  std::string body;
  body.reserve(blocks * static_cast<std::size_t>(LZ4_compressBound(static_cast<int>(kBlockSize))));
  std::vector<char> buffer(static_cast<std::size_t>(LZ4_compressBound(static_cast<int>(kBlockSize))));
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t size = std::min(kBlockSize, bytes.size() - b * kBlockSize);
    const int written = LZ4_compress_default(bytes.data() + b * kBlockSize, buffer.data(), static_cast<int>(size),
                                             static_cast<int>(buffer.size()));
    if (written <= 0) throw Error(name, "LZ4 could not compress an array's block");
    header[3 + b] = static_cast<uint32_t>(written);
    body.append(buffer.data(), static_cast<std::size_t>(written));
  }
  return bytesOf(header) + body;
}

std::string escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// 11 significant digits, as VTK gives ranges, whatever the locale.
std::string number(double value) {
  char text[32];
  const auto written = std::to_chars(text, text + sizeof text, value, std::chars_format::general, 11);
  return std::string(text, written.ptr);
}

// The DataArray element for `array`, its data at `offset` in the appended
// block. Field data and strings carry their count (VTK's reader sizes them by
// it); a piece's arrays take theirs from the piece.
std::string element(const DataArray& array, std::size_t offset, const std::string& indent, bool fieldData) {
  std::string xml = indent + "<DataArray type=\"" + array.type + "\" Name=\"" + escaped(array.name) + "\"";
  if (array.components != 1) xml += " NumberOfComponents=\"" + std::to_string(array.components) + "\"";
  if (fieldData || array.type == "String") xml += " NumberOfTuples=\"" + std::to_string(array.tuples) + "\"";
  xml += " format=\"appended\"";
  if (array.hasRange) xml += " RangeMin=\"" + number(array.rangeMin) + "\" RangeMax=\"" + number(array.rangeMax) + "\"";
  return xml + " offset=\"" + std::to_string(offset) + "\"/>\n";
}

}  // namespace

DataArray float64Array(const std::string& name, const Eigen::Ref<const Eigen::MatrixXd>& rows) {
  const auto components = static_cast<int>(rows.cols());
  if (components < 1) throw Error("internal: a VTK array's tuples have no values");
  DataArray array{name, "Float64", components, std::string(sizeof(double) * rows.size(), '\0'),
                  static_cast<int64_t>(rows.rows())};
  // The tuples one after the other, as VTK reads them.
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      reinterpret_cast<double*>(array.bytes.data()), rows.rows(), rows.cols()) = rows;
  if (array.tuples > 0) {
    // VTK's range of a vector array is that of its magnitudes.
    const Eigen::VectorXd values = components > 1 ? Eigen::VectorXd(rows.rowwise().norm()) : Eigen::VectorXd(rows.col(0));
    array.hasRange = true;
    array.rangeMin = values.minCoeff();
    array.rangeMax = values.maxCoeff();
  }
  return array;
}

DataArray float64Array(const std::string& name, const std::vector<double>& values, int components) {
  if (components < 1 || values.size() % static_cast<std::size_t>(components) != 0)
    throw Error("internal: a VTK array's values do not fill its tuples");
  return float64Array(name, Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
                                values.data(), static_cast<Eigen::Index>(values.size()) / components, components));
}

DataArray int64Array(const std::string& name, const std::vector<int64_t>& values, bool withRange) {
  return integerArray(name, "Int64", values, withRange);
}

DataArray int32Array(const std::string& name, const std::vector<int32_t>& values, bool withRange) {
  return integerArray(name, "Int32", values, withRange);
}

DataArray uint8Array(const std::string& name, const std::vector<uint8_t>& values, bool withRange) {
  return integerArray(name, "UInt8", values, withRange);
}

DataArray stringArray(const std::string& name, const std::vector<std::string>& strings) {
  DataArray array{name, "String", 1, "", static_cast<int64_t>(strings.size())};
  for (const std::string& s : strings) {
    if (s.find('\0') != std::string::npos) throw Error("internal: a VTK string holds a null character");
    array.bytes += s;
    array.bytes += '\0';
  }
  return array;
}

void writeDataset(const Dataset& data, const std::string& path, const std::string& name) {
  std::string xml = "<?xml version=\"1.0\"?>\n<VTKFile type=\"" + data.type +
                    "\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt32\" "
                    "compressor=\"vtkLZ4DataCompressor\">\n  <" + data.type + ">\n";
  std::string appended;
  auto add = [&](const DataArray& array, const std::string& indent, bool fieldData) {
    xml += element(array, appended.size(), indent, fieldData);
    appended += compressed(array.bytes, name);
  };
  if (!data.fieldData.empty()) {
    xml += "    <FieldData>\n";
    for (const DataArray& array : data.fieldData) add(array, "      ", true);
    xml += "    </FieldData>\n";
  }
  xml += "    <Piece" + data.pieceAttributes + ">\n";
  for (const Section& section : data.sections) {
    xml += "      <" + section.tag + section.attributes + ">\n";
    for (const DataArray& array : section.arrays) add(array, "        ", false);
    xml += "      </" + section.tag + ">\n";
  }
  xml += "    </Piece>\n  </" + data.type + ">\n  <AppendedData encoding=\"raw\">\n   _";
  const std::string tail = "\n  </AppendedData>\n</VTKFile>\n";

  std::ofstream out(path, std::ios::binary);
  if (!out) throw writeFailure(name);
  out.write(xml.data(), static_cast<std::streamsize>(xml.size()));
  out.write(appended.data(), static_cast<std::streamsize>(appended.size()));
  out.write(tail.data(), static_cast<std::streamsize>(tail.size()));
  out.close();
  if (!out) throw writeFailure(name);
}

}  // namespace dynsub::vtkxml
