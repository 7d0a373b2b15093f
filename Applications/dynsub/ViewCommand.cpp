// dynsub view: the interactive viewer (Viewer.h).
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "Commands.h"
#include "dynsub/Error.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Viewer.h"

namespace dynsub::app {

namespace {

struct Arguments {
  std::string image, landmarks, surface;
  SegmentParameters parameters;
};

void runView(const Arguments& o) {
  ViewerInput input;
  input.image = readVolume(o.image);
  if (!o.landmarks.empty()) {
    input.landmarksPath = o.landmarks;
    // A file that does not exist yet is where the new landmarks will be saved.
    if (std::filesystem::exists(o.landmarks)) {
      // The viewer edits one structure's points and saves them as one list:
      // a markups file of several would lose its structures.
      const std::vector<LandmarkList> lists = readLandmarkLists(o.landmarks);
      if (lists.size() > 1)
        throw Error(o.landmarks, "holds " + std::to_string(lists.size()) +
                                     " lists of points: view edits one structure's points and saves them as one "
                                     "list; give a file with one list");
      input.landmarks = lists.front().landmarks;
    }
  }
  input.surfacePath = o.surface;
  // A live fit pulls the surface to the landmarks on the slices.
  input.segment = segmentOptions(o.parameters, true);
  input.initialFraction = o.parameters.initialFraction;
  std::cout << "dynsub view: press h in the window for the mouse and key bindings\n";
  Viewer viewer(std::move(input));
  viewer.run();
}

}  // namespace

void addViewCommand(CLI::App& app) {
  auto o = std::make_shared<Arguments>();
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
  addSegmentParameterOptions(*command, o->parameters);
  command->callback([o] { runView(*o); });
}

}  // namespace dynsub::app
