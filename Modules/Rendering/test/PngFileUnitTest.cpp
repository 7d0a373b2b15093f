// The figures' PNG files (PngFile.h), read back by VTK's own PNG reader:
// every sample as written, whatever the size and channels, and a clear error
// for a file that cannot be written. Needs no display.
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "PngFile.h"
#include "ScratchFiles.h"
#include "dynsub/Error.h"

namespace dynsub {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) { return scratchFile("PngFile", name); }

// Samples that exercise the "up" filter's wrap-around (a row below a
// brighter one) and runs that deflate well, bottom row first.
std::vector<unsigned char> pattern(int width, int height, int channels) {
  std::vector<unsigned char> samples(static_cast<std::size_t>(width) * height * channels);
  unsigned state = 12345;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    state = state * 1103515245u + 12345u;
    samples[i] = i % 7 < 3 ? static_cast<unsigned char>(state >> 16) : static_cast<unsigned char>(255 * (i % 2));
  }
  return samples;
}

TEST(PngFile, VtksReaderGetsEverySampleBack) {
  for (const int channels : {3, 4})
    for (const auto& [width, height] : std::vector<std::pair<int, int>>{{1, 1}, {7, 5}, {240, 3}, {3, 240}}) {
      const std::vector<unsigned char> samples = pattern(width, height, channels);
      const fs::path path = scratch("pattern.png");
      writePngFile(path.string(), width, height, channels, samples.data());
      vtkNew<vtkPNGReader> reader;
      ASSERT_TRUE(reader->CanReadFile(path.c_str())) << width << " x " << height;
      reader->SetFileName(path.c_str());
      reader->Update();
      vtkImageData* image = reader->GetOutput();
      int size[3];
      image->GetDimensions(size);
      ASSERT_EQ(size[0], width);
      ASSERT_EQ(size[1], height);
      ASSERT_EQ(image->GetNumberOfScalarComponents(), channels);
      // VTK's images hold the bottom row first, as the writer was given them.
      const auto* read = static_cast<const unsigned char*>(image->GetScalarPointer());
      for (std::size_t i = 0; i < samples.size(); ++i)
        ASSERT_EQ(read[i], samples[i]) << width << " x " << height << " x " << channels << ", sample " << i;
    }
}

// The resolution a figure is meant to be printed at, as the pHYs chunk
// holds it: pixels per metre (300 dpi is 11811), the same across and down,
// unit 1 (the metre).
TEST(PngFile, RecordsItsPrintResolution) {
  const std::vector<unsigned char> samples = pattern(8, 8, 3);
  const fs::path path = scratch("300dpi.png");
  writePngFile(path.string(), 8, 8, 3, samples.data(), 300.0);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = bytes.find("pHYs");
  ASSERT_NE(at, std::string::npos);
  ASSERT_LT(bytes.find("pHYs"), bytes.find("IDAT"));  // the format puts it before the image data
  auto bigEndian = [&](std::size_t from) {
    std::uint32_t value = 0;
    for (std::size_t i = 0; i < 4; ++i) value = value << 8 | static_cast<unsigned char>(bytes[from + i]);
    return value;
  };
  EXPECT_EQ(bigEndian(at - 4), 9u);  // the chunk's length
  EXPECT_EQ(bigEndian(at + 4), 11811u);
  EXPECT_EQ(bigEndian(at + 8), 11811u);
  EXPECT_EQ(bytes[at + 12], 1);
  EXPECT_THROW(writePngFile(scratch("bad.png").string(), 4, 4, 3, samples.data(), 0.0), Error);
}

TEST(PngFile, AFileThatCannotBeWrittenIsAnErrorNamingIt) {
  const std::vector<unsigned char> samples = pattern(4, 4, 3);
  const std::string path = (scratch("missing") / "directory" / "figure.png").string();
  try {
    writePngFile(path, 4, 4, 3, samples.data());
    FAIL() << "a PNG was written into a missing directory";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(writePngFile(scratch("bad.png").string(), 0, 4, 3, samples.data()), Error);
  EXPECT_THROW(writePngFile(scratch("bad.png").string(), 4, 4, 2, samples.data()), Error);
}

}  // namespace
}  // namespace dynsub
