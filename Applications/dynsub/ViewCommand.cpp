// dynsub view: the interactive viewer (Viewer.h).
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>

#include "Commands.h"
#include "dynsub/Error.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Viewer.h"

namespace dynsub::app {

namespace {

struct ViewCommandOptions {
  std::string image, landmarks, surface;
  SegmentOptions segment;
};

void runView(const ViewCommandOptions& o) {
  ViewerInput input;
  input.image = readVolume(o.image);
  if (!o.landmarks.empty()) {
    input.landmarksPath = o.landmarks;
    // A file that does not exist yet is where the new landmarks will be saved.
    if (std::filesystem::exists(o.landmarks)) input.landmarks = readLandmarks(o.landmarks);
  }
  input.surfacePath = o.surface;
  checkSegmentOptions(o.segment);
  input.segment = o.segment;
  std::cout << "dynsub view: press h in the window for the mouse and key bindings\n";
  Viewer viewer(std::move(input));
  viewer.run();
}

}  // namespace

void addViewCommand(CLI::App& app) {
  auto o = std::make_shared<ViewCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "view",
      "Interactive viewer: axial, coronal and sagittal slices and a 3D view. Place, move and delete landmarks "
      "on the slices, save them (.mrk.json), and watch the surface fit live (space starts, pauses and resumes; "
      "Ctrl + drag in the 3D view pulls the surface). Press h in the window for all bindings. Needs an X display.");
  command->add_option("IMAGE", o->image, "3D image: .nii/.nii.gz, .nrrd, .mha/.mhd, or a DICOM series directory")
      ->required();
  command->add_option("--landmarks", o->landmarks,
                      "Landmarks to show and edit (.mrk.json, .fcsv, .csv); read if the file exists, and where "
                      "s saves them (default landmarks.mrk.json)");
  command->add_option("--surface", o->surface, "A surface to show (e.g. segment's surface.vtp), LPS mm");
  command->add_option("--image-force", o->segment.imageForce, "Image force k for fitting, N/mm^2")
      ->default_val(o->segment.imageForce);
  command->add_option("--landmark-stiffness", o->segment.landmarkStiffness, "Spring stiffness per landmark, N/mm")
      ->default_val(o->segment.landmarkStiffness);
  command->callback([o] { runView(*o); });
}

}  // namespace dynsub::app
