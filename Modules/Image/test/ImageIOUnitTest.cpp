#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

#include <zlib.h>

#include "ScratchFiles.h"
#include "TestGrids.h"
#include "dynsub/Error.h"
#include "dynsub/ImageIO.h"

namespace dynsub {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) { return scratchFile("Image", name); }

TEST(ImageGeometry, IndexAndPhysicalAreInverse) {
  const ImageGeometry g = grid({10, 20, 30}, Vector3(0.5, 1.0, 2.0), Vector3(-3, 4, 5), skewDirection());
  const Vector3 index(1.5, -2.25, 7.0);
  EXPECT_LT((g.toIndex(g.toPhysical(index)) - index).norm(), 1e-12);
  // One step along k moves 2 mm along the direction's third column.
  EXPECT_LT((g.toPhysical(Vector3(0, 0, 1)) - g.origin - 2.0 * g.direction.col(2)).norm(), 1e-12);
}

TEST(ImageIO, MaskRoundTripKeepsGeometryAndVoxels) {
  Mask mask{grid({7, 5, 4}, Vector3(0.7, 1.1, 2.5), Vector3(12, -30, 8), skewDirection()), {}};
  mask.voxels.resize(mask.geometry.voxelCount());
  for (std::size_t v = 0; v < mask.voxels.size(); ++v) mask.voxels[v] = (v * 7919) % 3 == 0;
  // Every single-file format (the size checks of truncated files must pass whole ones).
  for (const std::string name : {"roundtrip.nii.gz", "roundtrip.nii", "roundtrip.nrrd", "roundtrip.mha"}) {
    const fs::path path = scratch(name);
    writeMask(mask, path.string());
    const Volume read = readVolume(path.string());
    EXPECT_EQ(read.geometry.size, mask.geometry.size) << name;
    // NIfTI stores spacing and the affine in single precision.
    EXPECT_LT((read.geometry.spacing - mask.geometry.spacing).norm(), 1e-5) << name;
    EXPECT_LT((read.geometry.origin - mask.geometry.origin).norm(), 1e-4) << name;
    EXPECT_LT((read.geometry.direction - mask.geometry.direction).norm(), 1e-5) << name;
    for (std::size_t v = 0; v < mask.voxels.size(); ++v) ASSERT_EQ(read.voxels[v], mask.voxels[v]) << name << v;
  }
}

// The NRRD header's "key:=value" pairs (the header ends at the first empty
// line; the gzip data follows).
std::map<std::string, std::string> nrrdFields(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::map<std::string, std::string> fields;
  std::string line;
  while (std::getline(in, line) && !line.empty()) {
    const std::size_t split = line.find(":=");
    if (split != std::string::npos) fields[line.substr(0, split)] = line.substr(split + 2);
  }
  return fields;
}

// Three structures as 3D Slicer reads a segmentation: the voxels come back as
// written (ITK's NRRD reader, which Slicer's own reader is built on), and
// the header names each segment with its label, colour and extent.
TEST(ImageIO, SlicerSegmentationNamesItsSegments) {
  Volume labels{grid({6, 5, 4}, Vector3(0.5, 1.0, 1.5), Vector3(3, -2, 1), skewDirection()), {}};
  labels.voxels.assign(labels.geometry.voxelCount(), 0.0f);
  labels.voxels[labels.geometry.offset(1, 2, 3)] = 2;
  labels.voxels[labels.geometry.offset(4, 0, 1)] = 2;
  labels.voxels[labels.geometry.offset(5, 4, 0)] = 7;
  const std::vector<SlicerSegment> segments = {
      {2, "Caudate L", {0.25, 0.5, 0.75}}, {7, "putamen", {1, 0, 0}}, {9, "pallidum", {0, 1, 0}}};
  const fs::path path = scratch("three.seg.nrrd");
  writeSlicerSegmentation(labels, segments, path.string());
  const Volume read = readVolume(path.string());
  EXPECT_EQ(read.geometry.size, labels.geometry.size);
  EXPECT_LT((read.geometry.direction - labels.geometry.direction).norm(), 1e-9);
  for (std::size_t v = 0; v < labels.voxels.size(); ++v) ASSERT_EQ(read.voxels[v], labels.voxels[v]) << v;
  const std::map<std::string, std::string> fields = nrrdFields(path);
  EXPECT_EQ(fields.at("Segmentation_SourceRepresentation"), "Binary labelmap");
  EXPECT_EQ(fields.at("Segment0_Name"), "Caudate L");
  EXPECT_EQ(fields.at("Segment0_LabelValue"), "2");
  EXPECT_EQ(fields.at("Segment0_Color"), "0.25 0.5 0.75");
  EXPECT_EQ(fields.at("Segment0_Layer"), "0");
  EXPECT_EQ(fields.at("Segment1_Name"), "putamen");
  // Every segment of the layer, the empty one too, gives the whole grid:
  // Slicer crops a layer to its first segment's extent.
  for (const char* key : {"Segment0_Extent", "Segment1_Extent", "Segment2_Extent"})
    EXPECT_EQ(fields.at(key), "0 5 0 4 0 3") << key;
  EXPECT_EQ(fields.count("Segment3_ID"), 0u);
  // IDs are unique, as Slicer requires.
  EXPECT_NE(fields.at("Segment0_ID"), fields.at("Segment1_ID"));

  // Refused, naming the file, and nothing written: a voxel no segment
  // claims, a repeated label, a name with a line break, another extension.
  const fs::path refused = scratch("refused.seg.nrrd");
  const auto refuses = [&](const Volume& v, const std::vector<SlicerSegment>& s, const fs::path& p,
                           const std::string& why) {
    try {
      writeSlicerSegmentation(v, s, p.string());
      ADD_FAILURE() << "written: " << why;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(p));
  };
  refuses(labels, {segments[0]}, refused, "no segment's label");
  Volume halves = labels;
  halves.voxels[0] = 2.5f;
  refuses(halves, segments, refused, "no segment's label");
  refuses(labels, {segments[0], {2, "again", {0, 0, 0}}, segments[1]}, refused, "given to two segments");
  refuses(labels, {segments[0], {7, "two\nlines", {0, 0, 0}}}, refused, "control characters");
  refuses(labels, segments, scratch("labels.nrrd"), ".seg.nrrd");
}

// A MetaImage header with its voxels in a separate raw file, as other tools
// write it (writeMask refuses to: its header would name a temporary file).
TEST(ImageIO, MetaImageWithADataFile) {
  const fs::path header = scratch("detached.mhd"), data = scratch("detached.raw");
  std::ofstream(header) << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
                           "CompressedData = False\nTransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 3 -2 1\n"
                           "ElementSpacing = 0.5 1 2\nDimSize = 4 3 2\nElementType = MET_UCHAR\n"
                           "ElementDataFile = detached.raw\n";
  std::string voxels;
  for (int v = 0; v < 24; ++v) voxels.push_back(static_cast<char>(v));
  std::ofstream(data, std::ios::binary) << voxels;
  const Volume read = readVolume(header.string());
  EXPECT_EQ(read.geometry.size, (std::array<int, 3>{4, 3, 2}));
  EXPECT_LT((read.geometry.spacing - Vector3(0.5, 1, 2)).norm(), 1e-12);
  EXPECT_LT((read.geometry.origin - Vector3(3, -2, 1)).norm(), 1e-12);
  for (int v = 0; v < 24; ++v) ASSERT_EQ(read.voxels[v], v);
  // The data file cut short: refused, naming it.
  fs::resize_file(data, 20);
  try {
    readVolume(header.string());
    ADD_FAILURE() << "a short data file was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("detached.raw: truncated"), std::string::npos) << e.what();
  }
  Mask mask{read.geometry, std::vector<std::uint8_t>(24, 1)};
  EXPECT_THROW(writeMask(mask, scratch("written.mhd").string()), Error);
  EXPECT_FALSE(fs::exists(scratch("written.mhd")));
}

TEST(ImageIO, BadFilesAreRefusedWithTheirName) {
  EXPECT_THROW(readVolume(scratch("missing.nii.gz").string()), Error);
  // One slice: not a 3D image.
  Mask slice{grid({8, 8, 1}, Vector3::Ones(), Vector3::Zero(), Matrix3::Identity()), {}};
  slice.voxels.assign(64, 1);
  writeMask(slice, scratch("slice.nii.gz").string());
  try {
    readVolume(scratch("slice.nii.gz").string());
    FAIL() << "a single slice was read as a volume";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a 3D image"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("slice.nii.gz"), std::string::npos) << e.what();
  }
  // Truncated: the header survives, the voxels do not. The voxels are
  // pseudo-random so that compressed files are large enough for their header
  // to survive a cut to 3/4 (a .nii.gz cut short used to read as zeros).
  Mask big{grid({40, 40, 40}, Vector3::Ones(), Vector3::Zero(), Matrix3::Identity()), {}};
  big.voxels.resize(big.geometry.voxelCount());
  unsigned state = 1;
  for (auto& voxel : big.voxels) voxel = ((state = state * 1103515245u + 12345u) >> 16) & 1u;
  for (const std::string name : {"whole.nii", "whole.nii.gz", "whole.nrrd", "whole.mha"}) {
    const fs::path whole = scratch(name);
    writeMask(big, whole.string());
    fs::resize_file(whole, fs::file_size(whole) * 3 / 4);
    try {
      readVolume(whole.string());
      ADD_FAILURE() << name << " cut to 3/4 was read";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  std::ofstream(scratch("text.nii").string()) << "not an image\n";
  EXPECT_THROW(readVolume(scratch("text.nii").string()), Error);
}

// ---- Hostile numbers in image files: a clear error or a correct volume ----

// A NIfTI-1 file of float voxels, written byte by byte (the header fields
// DynSub and ITK read): `dims` may be larger than the voxels written, to make
// a header that lies.
void writeNifti(const fs::path& path, std::array<long, 3> dims, Vector3 spacing, const std::vector<float>& voxels,
                double srowScale = 1.0) {
  std::string header(352, '\0');
  auto put = [&header](std::size_t at, auto value) { std::memcpy(&header[at], &value, sizeof value); };
  put(0, std::int32_t{348});
  put(40, std::int16_t{3});
  for (int a = 0; a < 3; ++a) put(42 + 2 * a, static_cast<std::int16_t>(std::min<long>(dims[a], 32767)));
  put(70, std::int16_t{16});  // float32
  put(72, std::int16_t{32});
  put(76, 1.0f);
  for (int a = 0; a < 3; ++a) put(80 + 4 * a, static_cast<float>(spacing[a]));
  put(108, 352.0f);
  put(112, 1.0f);  // scl_slope
  header[123] = 10;  // mm, seconds
  put(254, std::int16_t{1});  // sform_code: scanner
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) put(280 + 16 * r + 4 * c, static_cast<float>(r == c ? srowScale * spacing[r] : 0.0));
  std::memcpy(&header[344], "n+1\0", 4);
  std::ofstream out(path, std::ios::binary);
  out << header;
  out.write(reinterpret_cast<const char*>(voxels.data()), static_cast<std::streamsize>(voxels.size() * sizeof(float)));
}

std::vector<float> ramp(std::size_t n, float scale) {
  std::vector<float> voxels(n);
  for (std::size_t v = 0; v < n; ++v) voxels[v] = scale * static_cast<float>(v % 17);
  return voxels;
}

// The error readVolume gives for `path`, or "" when it reads it.
std::string readError(const fs::path& path) {
  try {
    readVolume(path.string());
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

// Writes `from` gzipped to `to`, as `members` gzip members one after another
// (as bgzip and concatenated .gz files have them).
void gzipFile(const fs::path& from, const fs::path& to, int members = 1) {
  std::ifstream in(from, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  fs::remove(to);
  const std::size_t piece = bytes.size() / members + 1;
  for (std::size_t at = 0; at < bytes.size(); at += piece) {
    gzFile out = gzopen(to.c_str(), "ab");
    ASSERT_NE(out, nullptr);
    const auto size = static_cast<unsigned>(std::min(piece, bytes.size() - at));
    ASSERT_EQ(gzwrite(out, bytes.data() + at, size), static_cast<int>(size));
    ASSERT_EQ(gzclose(out), Z_OK);
  }
}

TEST(HostileImages, NanAndInfiniteVoxelsAreRefusedWithTheFirstIndex) {
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::infinity()}) {
    std::vector<float> voxels = ramp(6 * 5 * 4, 1.0f);
    voxels[2 + 6 * (3 + 5 * 1)] = bad;
    voxels[100] = bad;
    writeNifti(scratch("bad_voxels.nii"), {6, 5, 4}, Vector3(1, 1, 1), voxels);
    gzipFile(scratch("bad_voxels.nii"), scratch("bad_voxels.nii.gz"));
    for (const std::string name : {"bad_voxels.nii", "bad_voxels.nii.gz"}) {
      const std::string error = readError(scratch(name));
      EXPECT_NE(error.find(name + ": 2 voxel(s) are NaN or infinite, the first at index (2, 3, 1)"), std::string::npos)
          << error;
    }
  }
}

// A .nii.gz of several gzip members reads as the plain file; one cut short
// inside its last member is refused, naming the file.
TEST(HostileImages, GzipMembersAreReadOneAfterAnotherAndACutStreamIsRefused) {
  const std::vector<float> voxels = ramp(9 * 8 * 7, 0.5f);
  writeNifti(scratch("members.nii"), {9, 8, 7}, Vector3(1, 1, 1), voxels);
  gzipFile(scratch("members.nii"), scratch("members.nii.gz"), 3);
  const Volume plain = readVolume(scratch("members.nii").string());
  const Volume members = readVolume(scratch("members.nii.gz").string());
  EXPECT_EQ(members.voxels, plain.voxels);
  const auto size = fs::file_size(scratch("members.nii.gz"));
  fs::resize_file(scratch("members.nii.gz"), size - 10);
  EXPECT_NE(readError(scratch("members.nii.gz")).find("members.nii.gz: truncated or corrupt compressed data"),
            std::string::npos);
}

// Compressed or not by the file's first bytes: an uncompressed file named
// .nii.gz reads as the .nii (ITK's reader takes it too); a compressed one
// named .nii, which ITK's reader would take for raw bytes, is refused.
TEST(HostileImages, NiftiCompressionIsTakenFromTheContent) {
  const std::vector<float> voxels = ramp(5 * 4 * 3, 2.0f);
  writeNifti(scratch("plain.nii"), {5, 4, 3}, Vector3(1, 1, 1), voxels);
  fs::copy_file(scratch("plain.nii"), scratch("plain_named.nii.gz"), fs::copy_options::overwrite_existing);
  EXPECT_EQ(readVolume(scratch("plain_named.nii.gz").string()).voxels, voxels);
  gzipFile(scratch("plain.nii"), scratch("packed_named.nii"));
  EXPECT_NE(readError(scratch("packed_named.nii"))
                .find("packed_named.nii: compressed with gzip, but named as an uncompressed NIfTI file"),
            std::string::npos);
}

// ITK keeps NaN in MetaImage and NRRD files; readVolume refuses them there too.
TEST(HostileImages, NanVoxelsInMetaImageAndNrrdFilesAreRefused) {
  std::vector<float> voxels = ramp(4 * 3 * 2, 1.0f);
  voxels[7] = std::numeric_limits<float>::quiet_NaN();
  const std::string data(reinterpret_cast<const char*>(voxels.data()), voxels.size() * sizeof(float));
  std::ofstream(scratch("nan.mha"), std::ios::binary)
      << "ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n" << data;
  std::ofstream(scratch("nan.nrrd"), std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nsizes: 4 3 2\nencoding: raw\nendian: little\n\n" << data;
  for (const std::string name : {"nan.mha", "nan.nrrd"}) {
    const std::string error = readError(scratch(name));
    EXPECT_NE(error.find(name + ": 1 voxel(s) are NaN or infinite, the first at index (3, 1, 0)"), std::string::npos)
        << error;
  }
}

// ITK would make one value of each voxel's several (a colour's luminance, a
// vector's first component); readVolume refuses them, as it does NIfTI's.
TEST(HostileImages, SeveralValuesPerVoxelAreRefused) {
  const std::vector<float> voxels = ramp(2 * 4 * 3 * 2, 1.0f);
  const std::string data(reinterpret_cast<const char*>(voxels.data()), voxels.size() * sizeof(float));
  std::ofstream(scratch("channels.mha"), std::ios::binary)
      << "ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\nElementNumberOfChannels = 2\nElementType = MET_FLOAT\n"
         "ElementDataFile = LOCAL\n"
      << data;
  std::ofstream(scratch("channels.nrrd"), std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 4\nspace: left-posterior-superior\nsizes: 2 4 3 2\n"
         "kinds: vector domain domain domain\nspace directions: none (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\n"
         "endian: little\nspace origin: (0,0,0)\n\n"
      << data;
  for (const std::string name : {"channels.mha", "channels.nrrd"}) {
    const std::string error = readError(scratch(name));
    EXPECT_NE(error.find(name + ": an image of 2 values per voxel"), std::string::npos) << error;
  }
}

// ITK reads a 4D file's first volume, and keeps a sheared or scaled direction
// matrix as written: both refused, naming what the file holds.
TEST(HostileImages, FourDimensionsAndAxesNotAtRightAnglesAreRefused) {
  const std::vector<float> voxels = ramp(4 * 3 * 2 * 2, 1.0f);
  const std::string data(reinterpret_cast<const char*>(voxels.data()), voxels.size() * sizeof(float));
  std::ofstream(scratch("fourd.mha"), std::ios::binary)
      << "ObjectType = Image\nNDims = 4\nDimSize = 4 3 2 2\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n"
      << data;
  EXPECT_NE(readError(scratch("fourd.mha")).find("fourd.mha: a 4D image (4 x 3 x 2 x 2 voxels)"), std::string::npos)
      << readError(scratch("fourd.mha"));
  const std::string volume = data.substr(0, data.size() / 2);
  for (const std::string matrix : {"1 0 0 0.5 1 0 0 0 1", "2 0 0 0 2 0 0 0 2"}) {
    std::ofstream(scratch("skewed.mha"), std::ios::binary)
        << "ObjectType = Image\nNDims = 3\nTransformMatrix = " << matrix
        << "\nDimSize = 4 3 2\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n"
        << volume;
    EXPECT_NE(readError(scratch("skewed.mha")).find("skewed.mha: the direction matrix is not orthonormal"),
              std::string::npos)
        << matrix << ": " << readError(scratch("skewed.mha"));
  }
  // A placement field that is not a number, or of the wrong count: MetaIO
  // fails on it and then reports the file missing.
  for (const auto& [field, message] : std::vector<std::pair<std::string, std::string>>{
           {"ElementSpacing = nan 1 1", "ElementSpacing holds 'nan', not a finite number"},
           {"TransformMatrix = 1 0 0 0 1", "TransformMatrix has 5 values for NDims 3 (expected 9)"},
           {"Offset = 0 0", "Offset has 2 values for NDims 3 (expected 3)"}}) {
    std::ofstream(scratch("placed.mha"), std::ios::binary)
        << "ObjectType = Image\nNDims = 3\n"
        << field << "\nDimSize = 4 3 2\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n"
        << volume;
    EXPECT_NE(readError(scratch("placed.mha")).find("placed.mha: MetaImage " + message), std::string::npos)
        << readError(scratch("placed.mha"));
  }
  // A rotation written to 6 decimals reads.
  std::ofstream(scratch("rotated.mha"), std::ios::binary)
      << "ObjectType = Image\nNDims = 3\nTransformMatrix = 0.866025 0.5 0 -0.5 0.866025 0 0 0 1"
      << "\nDimSize = 4 3 2\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n"
      << volume;
  EXPECT_EQ(readError(scratch("rotated.mha")), "");
}

// A compressed MetaImage whose stream is damaged, or whose header announces
// fewer voxels than the stream holds: MetaIO prints "Uncompress failed" and
// ITK returns an image regardless. Pseudo-random voxels, as above.
TEST(HostileImages, CorruptCompressedMetaImageDataIsRefused) {
  Mask big{grid({40, 40, 40}, Vector3::Ones(), Vector3::Zero(), Matrix3::Identity()), {}};
  big.voxels.resize(big.geometry.voxelCount());
  unsigned state = 1;
  for (auto& voxel : big.voxels) voxel = ((state = state * 1103515245u + 12345u) >> 16) & 1u;
  const fs::path packed = scratch("packed.mha");
  writeMask(big, packed.string());
  std::string bytes;
  {
    std::ifstream in(packed, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::size_t data = bytes.find("ElementDataFile = LOCAL\n") + 24;
  std::string damaged = bytes;
  for (std::size_t at = data + 100; at < data + 110; ++at) damaged[at] = static_cast<char>(~damaged[at]);
  std::ofstream(scratch("damaged.mha"), std::ios::binary) << damaged;
  std::string error = readError(scratch("damaged.mha"));
  // Damage may end the stream early or late: only the verdict is certain.
  EXPECT_NE(error.find("damaged.mha: corrupt compressed data: it "), std::string::npos) << error;
  EXPECT_NE(error.find(" the 64000 bytes the header announces"), std::string::npos) << error;
  std::string shorter = bytes;
  shorter.replace(shorter.find("DimSize = 40 40 40"), 18, "DimSize = 40 40 39");
  std::ofstream(scratch("shorter.mha"), std::ios::binary) << shorter;
  error = readError(scratch("shorter.mha"));
  EXPECT_NE(error.find("shorter.mha: corrupt compressed data: it inflates to more than the 62400 bytes"),
            std::string::npos)
      << error;
  EXPECT_EQ(readError(scratch("packed.mha")), "");
}

// A header that announces less data than the file holds: ITK reads the
// first bytes as the image and drops the rest.
TEST(HostileImages, MoreDataThanTheHeaderAnnouncesIsRefused) {
  const std::vector<float> voxels = ramp(4 * 3 * 3, 1.0f);
  const std::string data(reinterpret_cast<const char*>(voxels.data()), voxels.size() * sizeof(float));
  std::ofstream(scratch("extra.mha"), std::ios::binary)
      << "ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n"
      << data;
  std::ofstream(scratch("extra.nrrd"), std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\nsizes: 4 3 2\n"
         "space directions: (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\nendian: little\nspace origin: (0,0,0)\n\n"
      << data;
  // The same data gzip-encoded, as 3D Slicer writes NRRD: measured inflated.
  std::ofstream(scratch("extra.raw"), std::ios::binary) << data;
  gzipFile(scratch("extra.raw"), scratch("extra.raw.gz"));
  {
    std::ifstream in(scratch("extra.raw.gz"), std::ios::binary);
    std::ofstream(scratch("extragz.nrrd"), std::ios::binary)
        << "NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\nsizes: 4 3 2\n"
           "space directions: (1,0,0) (0,1,0) (0,0,1)\nencoding: gzip\nendian: little\nspace origin: (0,0,0)\n\n"
        << in.rdbuf();
  }
  for (const std::string name : {"extra.mha", "extra.nrrd", "extragz.nrrd"}) {
    const std::string error = readError(scratch(name));
    EXPECT_NE(error.find(name + ": 144 bytes of data, where the header announces 96"), std::string::npos) << error;
  }
  // The data the header announces, to the byte, reads.
  std::ofstream(scratch("exact.nrrd"), std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\nsizes: 4 3 3\n"
         "space directions: (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\nendian: little\nspace origin: (0,0,0)\n\n"
      << data;
  EXPECT_EQ(readError(scratch("exact.nrrd")), "");
}

// The reading library's reason, without ITK's preamble (its class, an
// address) and the chain of "trouble reading" lines around it.
TEST(HostileImages, ALibrarysReasonIsGivenWithoutItsPreamble) {
  std::ofstream(scratch("detached.nhdr"))
      << "NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\nsizes: 4 3 2\n"
         "space directions: (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\nendian: little\nspace origin: (0,0,0)\n"
         "data file: nothere.raw\n";
  const std::string error = readError(scratch("detached.nhdr"));
  EXPECT_NE(error.find("detached.nhdr: cannot read image: "), std::string::npos) << error;
  EXPECT_NE(error.find("couldn't open \""), std::string::npos) << error;
  EXPECT_NE(error.find("nothere.raw\" (data file 1 of 1) for reading"), std::string::npos) << error;
  EXPECT_EQ(error.find("ERROR"), std::string::npos) << error;
  EXPECT_EQ(error.find("trouble reading"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

TEST(HostileImages, ConstantAndExtremeIntensitiesAreReadExactly) {
  // The ramp goes up to 16 times the scale: 2.4e38 of float's 3.4e38.
  for (const float scale : {0.0f, 1.5e37f, 1e-37f, -1.5e37f}) {
    const std::vector<float> voxels = scale == 0.0f ? std::vector<float>(60, 42.0f) : ramp(60, scale);
    writeNifti(scratch("extreme.nii"), {5, 4, 3}, Vector3(1, 1, 1), voxels);
    const Volume volume = readVolume(scratch("extreme.nii").string());
    ASSERT_EQ(volume.voxels.size(), voxels.size());
    for (std::size_t v = 0; v < voxels.size(); ++v) ASSERT_EQ(volume.voxels[v], voxels[v]) << "scale " << scale;
  }
}

TEST(HostileImages, SpacingOutsideWhatDynSubWorksWithIsRefused) {
  for (const double spacing : {1e-6, 1e5}) {
    writeNifti(scratch("spacing.nii"), {4, 4, 4}, Vector3(1, spacing, 1), ramp(64, 1.0f));
    const std::string error = readError(scratch("spacing.nii"));
    EXPECT_NE(error.find("spacing.nii: voxel spacing"), std::string::npos) << error;
    EXPECT_NE(error.find("outside the 0.0001 to 10000 mm"), std::string::npos) << error;
  }
  // Near the limits (NIfTI stores spacing as float: 1e-4 itself reads as 9.99999975e-5).
  writeNifti(scratch("spacing.nii"), {4, 4, 4}, Vector3(2e-4, 1, 5e3), ramp(64, 1.0f));
  EXPECT_EQ(readError(scratch("spacing.nii")), "");
}

// Overwrites the bytes of `value` at `at` in the file `path`.
template <typename T>
void patch(const fs::path& path, std::size_t at, T value) {
  std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
  file.seekp(static_cast<std::streamoff>(at));
  file.write(reinterpret_cast<const char*>(&value), sizeof value);
}

TEST(HostileImages, NonFiniteOrientationsSeriesAndComplexVoxelsAreRefused) {
  const fs::path path = scratch("header.nii");
  auto fresh = [&] { writeNifti(path, {4, 4, 4}, Vector3(1, 1, 1), ramp(2 * 64, 1.0f)); };
  // A NaN in the sform's translation (ITK 5.2 aborts the process on it).
  fresh();
  patch(path, 280 + 12, std::numeric_limits<float>::quiet_NaN());
  std::string error = readError(path);
  EXPECT_NE(error.find("header.nii: a NIfTI header whose sform"), std::string::npos) << error;
  // An infinite qoffset with a qform code; the sform is not used (code 0).
  fresh();
  patch(path, 254, std::int16_t{0});
  patch(path, 252, std::int16_t{1});
  patch(path, 268, std::numeric_limits<float>::infinity());
  error = readError(path);
  EXPECT_NE(error.find("header.nii: a NIfTI header whose qform"), std::string::npos) << error;
  // The same NaN with qform code 0 is not read, and the file is.
  patch(path, 252, std::int16_t{0});
  patch(path, 254, std::int16_t{1});
  EXPECT_EQ(readError(path), "");
  // Two volumes (dim[0] 4, dim[4] 2); one volume in four dimensions is read.
  fresh();
  patch(path, 40, std::int16_t{4});
  patch(path, 48, std::int16_t{2});
  error = readError(path);
  EXPECT_NE(error.find("header.nii: a NIfTI image of 4 dimensions, 2 along axis 3"), std::string::npos) << error;
  patch(path, 48, std::int16_t{1});
  EXPECT_EQ(readError(path), "");
  // Complex voxels (complex64: two floats a voxel, as written).
  fresh();
  patch(path, 70, std::int16_t{32});
  patch(path, 72, std::int16_t{64});
  error = readError(path);
  EXPECT_NE(error.find("header.nii: a NIfTI image of complex voxels"), std::string::npos) << error;
}

// A sheared sform is passed over by ITK for the qform: refused where the two
// place the image more than half a voxel apart, read where they agree, or
// where the sform is not sheared (ITK then takes the sform).
TEST(HostileImages, AShearedSformThatTheQformContradictsIsRefused) {
  const fs::path path = scratch("sheared.nii");
  // 20 x 20 x 20 voxels of 1 mm; the qform (code 1, identity quaternion, no offset) is the identity.
  auto write = [&](float shear, float shift) {
    writeNifti(path, {20, 20, 20}, Vector3(1, 1, 1), ramp(8000, 1.0f));
    patch(path, 252, std::int16_t{1});
    patch(path, 280 + 4, shear);   // srow_x[1]: x grows with j
    patch(path, 280 + 12, shift);  // srow_x[3]
  };
  write(0.5f, 0.0f);  // the far corner 9.5 mm apart
  std::string error = readError(path);
  EXPECT_NE(error.find("sheared.nii: a NIfTI header whose sform is sheared"), std::string::npos) << error;
  EXPECT_NE(error.find("places the image up to 9.5 mm elsewhere"), std::string::npos) << error;
  write(0.02f, 0.0f);  // 0.38 mm apart at most: within half a voxel
  EXPECT_EQ(readError(path), "");
  write(0.0f, 5.0f);  // not sheared, 5 mm from the qform: ITK reads the sform
  EXPECT_EQ(readError(path), "");
}

// A sform whose code is not 1 (scanner) is passed over by ITK for the qform,
// where FSL and nibabel read the sform: refused where the two place the image
// more than half a voxel apart (as after a registration that set only the
// sform), read where they agree.
TEST(HostileImages, ASformThatITKPassesOverAndTheQformContradictsIsRefused) {
  const fs::path path = scratch("two_placements.nii");
  auto write = [&](std::int16_t sformCode, float shift) {
    writeNifti(path, {20, 20, 20}, Vector3(1, 1, 1), ramp(8000, 1.0f));
    patch(path, 252, std::int16_t{1});  // qform_code: scanner (the identity)
    patch(path, 254, sformCode);
    patch(path, 280 + 12, shift);  // srow_x[3]
  };
  write(4, 10.0f);  // MNI: the sform 10 mm from the qform
  std::string error = readError(path);
  EXPECT_NE(error.find("two_placements.nii: a NIfTI header whose qform and sform place the image up to 10.0 mm apart"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("fslorient -copysform2qform"), std::string::npos) << error;
  write(2, 0.3f);  // aligned, 0.3 mm apart: within half a voxel
  EXPECT_EQ(readError(path), "");
  write(1, 10.0f);  // scanner: ITK reads the sform, as FSL and nibabel do
  EXPECT_EQ(readError(path), "");
}

// ITK 5.2 does not read NIfTI-2: such a file is named as NIfTI-2, not as an
// unknown format.
TEST(HostileImages, NiftiTwoIsNamed) {
  const fs::path path = scratch("two.nii");
  {
    std::ofstream out(path, std::ios::binary);
    const std::int32_t size = 540;
    out.write(reinterpret_cast<const char*>(&size), 4);
    out << std::string(536 + 64, '\0');
  }
  const std::string error = readError(path);
  EXPECT_NE(error.find("two.nii: a NIfTI-2 file, which ITK 5.2 (DynSub's image reader) does not read"),
            std::string::npos)
      << error;
}

TEST(HostileImages, ADegenerateDirectionIsRefused) {
  // NRRD space directions with two parallel axes.
  std::ofstream(scratch("parallel.nrrd"), std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\nsizes: 2 2 2\n"
         "space directions: (1,0,0) (0,1,0) (1,0,0)\nencoding: raw\nendian: little\nspace origin: (0,0,0)\n\n"
      << std::string(32, '\0');
  const std::string error = readError(scratch("parallel.nrrd"));
  EXPECT_NE(error.find("parallel.nrrd"), std::string::npos) << error;
  EXPECT_FALSE(error.empty());
}

TEST(HostileImages, HeadersAnnouncingHugeImagesAreRefusedBeforeAllocating) {
  // 1000^3 float voxels (4 GB) announced by a file of a few bytes: truncated.
  writeNifti(scratch("huge.nii"), {1000, 1000, 1000}, Vector3(1, 1, 1), ramp(8, 1.0f));
  std::string error = readError(scratch("huge.nii"));
  EXPECT_NE(error.find("huge.nii: truncated"), std::string::npos) << error;
  // The same gzipped: a file that cannot inflate to what it announces.
  gzipFile(scratch("huge.nii"), scratch("huge.nii.gz"));
  error = readError(scratch("huge.nii.gz"));
  EXPECT_NE(error.find("huge.nii.gz: truncated"), std::string::npos) << error;
  // 32767^3 (1.3e5 GiB): more than any memory, in NIfTI, MetaImage and NRRD
  // (the last through ITK's header reader).
  writeNifti(scratch("huge.nii"), {32767, 32767, 32767}, Vector3(1, 1, 1), ramp(8, 1.0f));
  error = readError(scratch("huge.nii"));
  EXPECT_NE(error.find("huge.nii: the header announces 35181150961663 voxels"), std::string::npos) << error;
  EXPECT_NE(error.find(" GiB as float, more than "), std::string::npos) << error;
  std::ofstream(scratch("huge.mha"), std::ios::binary)
      << "ObjectType = Image\nNDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_FLOAT\n"
         "ElementDataFile = LOCAL\n" << std::string(64, '\0');
  error = readError(scratch("huge.mha"));
  EXPECT_NE(error.find("huge.mha: the header announces 1000000000000000 voxels"), std::string::npos) << error;
  std::ofstream(scratch("huge.nrrd"), std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\nendian: little\n\n"
      << std::string(64, '\0');
  error = readError(scratch("huge.nrrd"));
  EXPECT_NE(error.find("huge.nrrd: the header announces 1000000000000000 voxels"), std::string::npos) << error;
}

}  // namespace
}  // namespace dynsub
