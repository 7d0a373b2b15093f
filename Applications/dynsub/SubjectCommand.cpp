#include <algorithm>
#include <fstream>
#include <iostream>
#include <limits>
#include <set>
#include <string>

#include <CLI/CLI.hpp>

#include "Commands.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/ImageIO.h"
#include "dynsub/OutputSet.h"
#include "dynsub/SubjectGenerator.h"

namespace dynsub::app {

namespace {

struct Arguments {
  std::string image, labels, out;
  std::uint64_t seed = 1;
  std::vector<std::string> settings;  // key=value
};

void runSubject(const Arguments& arguments) {
  SubjectSettings settings;
  // An unknown key or a value out of range is a usage error here; the same
  // checks name the plan when a plan's cohort gives the settings.
  asUsageError([&] {
    std::set<std::string> given;
    for (const std::string& setting : arguments.settings) {
      const auto equals = setting.find('=');
      if (equals == std::string::npos) throw UsageError("--set", "expected KEY=VALUE, got '" + setting + "'");
      const std::string key = setting.substr(0, equals);
      // The last would win without a word, and the subject be another than meant.
      if (!given.insert(key).second) throw UsageError("--set", key + " is set twice");
      setSubjectSetting(settings, key, setting.substr(equals + 1));
    }
    checkSubjectSettings(settings);
  });
  for (const char* name : {"image.nii.gz", "labels.nii.gz", "subject.json"})
    for (const std::string& input : {arguments.image, arguments.labels})
      requireNotInput((std::filesystem::path(arguments.out) / name).string(), input);
  prepareOutputDirectory(arguments.out);
  const Volume image = readVolume(arguments.image);
  const Volume labels = readLabelMap(arguments.labels);
  const Subject subject = makeSubject(image, labels, settings, arguments.seed, {arguments.image, arguments.labels});
  // A ground truth with no label scores nothing: say so now, not when a
  // plan's structures find no voxel.
  if (std::none_of(subject.labels.voxels.begin(), subject.labels.voxels.end(), [](float v) { return v != 0; }))
    throw Error(arguments.labels, "no labelled voxel lies within the image " + arguments.image +
                                      ": the label map is empty or does not overlap the image");
  OutputSet outputs(arguments.out);
  writeVolume(subject.image, outputs.add("image.nii.gz"), VoxelType::Float32);
  writeVolume(subject.labels, outputs.add("labels.nii.gz"), VoxelType::Label16);
  {
    const std::string path = outputs.add("subject.json");
    std::ofstream out(path);
    out << subjectRecord(subject.draw) << '\n';
    if (!out.flush()) throw Error(path, "cannot be written");
  }
  outputs.commit();
  std::cout << "subject " << arguments.seed << ": " << subjectRecord(subject.draw) << "\nwrote " << arguments.out
            << "/image.nii.gz, labels.nii.gz, subject.json\n";
}

}  // namespace

void addSubjectCommand(CLI::App& app) {
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "subject",
      "Make a test subject with exact ground truth from an image and its label map: the anatomy moved by a "
      "random affine map and a smooth deformation that does not fold, then acquired again with a bias field, "
      "blur, Rician noise and, for some subjects, thick slices. Realistic subjects (the default) keep the "
      "source's intensities under another gamma; synthesized ones (--set mode=synthesized) draw them from the "
      "labels and the source's tissue classes, T1-like or T2-like, so that their edges are their labels' "
      "boundaries. The same seed gives the same subject. Writes image.nii.gz, labels.nii.gz (on the fine grid) "
      "and subject.json (what was drawn).");
  command->add_option("IMAGE", arguments->image, "The source image (NIfTI, NRRD, MetaImage or DICOM)")->required();
  command->add_option("LABELS", arguments->labels, "Its label map (integer labels, any grid)")->required();
  // Digits only, without a leading 0, and at most 2^64-1: the unsigned
  // reader takes "-1" and a longer number as 2^64-1, and "010" as octal 8,
  // other seeds than the one given.
  command->add_option("--seed", arguments->seed, "The subject's seed (a whole number, 0 to 2^64-1)")
      ->default_val(1)
      ->check([](const std::string& text) {
        const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos &&
                            (text.size() == 1 || text[0] != '0');
        const std::string largest = std::to_string(std::numeric_limits<std::uint64_t>::max());
        const bool fits =
            digits && (text.size() < largest.size() || (text.size() == largest.size() && text <= largest));
        return fits ? std::string() : "expected a whole number from 0 to " + largest + ", got '" + text + "'";
      });
  command->add_option("--set", arguments->settings,
                      "KEY=VALUE, repeatable: mode (realistic or synthesized), t2_fraction, label_spread, "
                      "structure_labels (L1,L2,...: the labels a synthesized subject draws as structures), "
                      "rotation_degrees, scale_spread, shear_spread, translation_mm, "
                      "warp_spacing_mm, warp_mm, gamma_spread, bias_spread, blur_mm (LOW,HIGH), snr (LOW,HIGH), "
                      "source_snr, thick_fraction, thick_mm, thick_axis (0, 1 or 2; drawn if not given)");
  command->add_option("--out", arguments->out, "Output directory")->required();
  command->callback([arguments] { runSubject(*arguments); });
}

}  // namespace dynsub::app
