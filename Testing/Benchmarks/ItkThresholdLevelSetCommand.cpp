// ITK's threshold level set as a whole command, the way an ITK user runs it:
// read the MRI and an initial mask with ITK's readers, run the filter on the
// mask's grid (a region of the image), write the labelmap on the image's grid
// with ITK's writer.
//   build/bin/ItkThresholdLevelSetCommand IMAGE INITIAL_MASK OUTPUT [WINDOW CURVATURE]
// (WINDOW: the intensity window in standard deviations of the voxels inside
// the initial mask, 1 unless given; CURVATURE 3 unless given: the settings of
// SegmentationComparison's head to head.) Tools/compare_segment_commands.sh
// times it against `dynsub segment`, taking turns; SegmentationComparison
// --write-initial writes the initial mask (DynSub's initial model, voxelized
// on DynSub's region of interest). Exit code 2 for a wrong command line, 1
// with a message on any other error, and no output file then.
#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageRegionConstIterator.h>
#include <itkNiftiImageIOFactory.h>
#include <itkRegionOfInterestImageFilter.h>

#include "ItkImages.h"
#include "ItkThresholdLevelSet.h"

namespace {

using dynsub::itkbridge::FloatImage;
using dynsub::itkbridge::MaskImage;

template <typename Image>
typename Image::Pointer read(const std::string& path) {
  auto reader = itk::ImageFileReader<Image>::New();
  reader->SetFileName(path);
  try {
    reader->Update();
  } catch (const itk::ExceptionObject& e) {
    throw std::runtime_error(path + ": cannot be read: " + e.GetDescription());
  }
  return reader->GetOutput();
}

template <typename Image, typename Pixel = typename Image::PixelType>
std::vector<Pixel> voxelsOf(const Image* image) {
  std::vector<Pixel> voxels;
  voxels.reserve(image->GetLargestPossibleRegion().GetNumberOfPixels());
  for (itk::ImageRegionConstIterator<Image> it(image, image->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
    voxels.push_back(it.Get());
  return voxels;
}

// The whole of `text` as a finite number, or an error naming `what`.
double number(const std::string& text, const char* what) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value))
    throw std::runtime_error(std::string(what) + " must be a number, got '" + text + "'");
  return value;
}

int run(int argc, char** argv) {
  if (argc != 4 && argc != 6) {
    std::fprintf(stderr, "usage: %s IMAGE INITIAL_MASK OUTPUT [WINDOW CURVATURE]\n", argv[0]);
    return 2;
  }
  const std::string output = argv[3];
  itk::NiftiImageIOFactory::RegisterOneFactory();  // NIfTI alone: see CMakeLists.txt
  itkbaseline::ThresholdLevelSetOptions options;
  options.window = argc == 6 ? number(argv[4], "WINDOW") : 1.0;
  options.curvature = argc == 6 ? number(argv[5], "CURVATURE") : 3.0;

  const FloatImage::Pointer image = read<FloatImage>(argv[1]);
  const MaskImage::Pointer initial = read<MaskImage>(argv[2]);

  // The mask's grid must be a region of the image's: same spacing and
  // direction, its first voxel centre on one of the image's.
  FloatImage::IndexType first;
  const bool inside = image->TransformPhysicalPointToIndex(initial->GetOrigin(), first);
  FloatImage::PointType firstCentre;
  image->TransformIndexToPhysicalPoint(first, firstCentre);
  const double tolerance = 1e-3 * image->GetSpacing()[0];
  bool aligned = inside && firstCentre.EuclideanDistanceTo(initial->GetOrigin()) < tolerance;
  for (int a = 0; a < 3; ++a) {
    aligned = aligned && std::abs(image->GetSpacing()[a] - initial->GetSpacing()[a]) < tolerance;
    for (int b = 0; b < 3; ++b)
      aligned = aligned && std::abs(image->GetDirection()(a, b) - initial->GetDirection()(a, b)) < 1e-6;
  }
  FloatImage::RegionType region(first, initial->GetLargestPossibleRegion().GetSize());
  if (!aligned || !image->GetLargestPossibleRegion().IsInside(region))
    throw std::runtime_error(std::string(argv[2]) + ": its grid is not a region of " + argv[1] + "'s");

  auto crop = itk::RegionOfInterestImageFilter<FloatImage, FloatImage>::New();
  crop->SetInput(image);
  crop->SetRegionOfInterest(region);
  crop->Update();
  const FloatImage* cropped = crop->GetOutput();

  const itkbaseline::ThresholdLevelSetResult result = itkbaseline::thresholdLevelSet(
      dynsub::itkbridge::geometryOf(cropped), voxelsOf(cropped), voxelsOf(initial.GetPointer()), {}, options);

  // The labelmap on the whole image's grid.
  auto labels = MaskImage::New();
  labels->CopyInformation(image);
  labels->SetRegions(image->GetLargestPossibleRegion());
  labels->Allocate(true);
  const auto size = region.GetSize();
  std::size_t n = 0;
  for (itk::IndexValueType k = 0; k < static_cast<itk::IndexValueType>(size[2]); ++k)
    for (itk::IndexValueType j = 0; j < static_cast<itk::IndexValueType>(size[1]); ++j)
      for (itk::IndexValueType i = 0; i < static_cast<itk::IndexValueType>(size[0]); ++i, ++n)
        labels->SetPixel({{first[0] + i, first[1] + j, first[2] + k}}, result.mask[n]);

  auto writer = itk::ImageFileWriter<MaskImage>::New();
  writer->SetInput(labels);
  writer->SetFileName(output);
  writer->UseCompressionOn();
  try {
    writer->Update();
  } catch (const itk::ExceptionObject& e) {
    std::remove(output.c_str());
    throw std::runtime_error(output + ": cannot be written: " + e.GetDescription());
  }
  std::printf("%d iterations, window %.1f..%.1f\n", result.elapsedIterations, result.lower, result.upper);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ItkThresholdLevelSetCommand: %s\n", e.what());
    return 1;
  }
}
