#include "dynsub/SurfaceWriter.h"

#include <algorithm>
#include <filesystem>

#include <vtkCallbackCommand.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkErrorCode.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkWriter.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkLZ4DataCompressor.h>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/SurfacePolyData.h"
#include "GeometryFormats.h"

namespace dynsub {

std::vector<std::string> triangleSurfaceExtensions() { return {".vtp", ".obj", ".ply", ".stl"}; }

void writeTriangleSurface(const TriangleSurface& surface, const std::string& path,
                          const std::vector<PointScalars>& scalars, const std::string& space) {
  const std::string extension = lowerCaseExtension(path);
  const std::vector<std::string> known = triangleSurfaceExtensions();
  if (std::find(known.begin(), known.end(), extension) == known.end()) {
    throw Error(path, "unknown surface format '" + extension + "' (expected .vtp, .obj, .ply or .stl)");
  }
  if (!surface.points.allFinite()) throw Error(path, "the surface has non-finite coordinates; nothing written");
  for (const PointScalars& s : scalars)
    if (s.values.size() != surface.points.rows() || !s.values.allFinite())
      throw Error(path, "point data '" + s.name + "' needs one finite value per point; nothing written");
  if (!space.empty() && space != "LPS" && space != "RAS")
    throw Error(path, "unknown coordinate space '" + space + "' (expected LPS or RAS)");
  AtomicOutput output(path);
  vtkSmartPointer<vtkPolyData> polyData = toPolyData(surface);
  for (const PointScalars& s : scalars) addPointData(polyData, s.name, s.values);
  if (!space.empty()) {
    vtkNew<vtkStringArray> array;
    array->SetName("SPACE");
    array->InsertNextValue(space);
    polyData->GetFieldData()->AddArray(array);
  }
  // VTK's writers can return success on a full disk (an XML writer cut
  // short at 16 KiB returned 1, measured): their error code tells.
  // VTK's own account of a failed write (the writer's error, then its
  // pipeline's dump of the request) is taken by an observer that drops it:
  // the error below names the file and the cause in one line.
  vtkNew<vtkCallbackCommand> quiet;
  // `writer`'s file name is set (the temporary file).
  auto write = [&](auto* writer) {
    writer->SetInputData(polyData);
    vtkObject* const sources[] = {writer, writer->GetExecutive()};
    for (vtkObject* source : sources) {
      source->AddObserver(vtkCommand::ErrorEvent, quiet);
      source->AddObserver(vtkCommand::WarningEvent, quiet);
    }
    const int written = writer->Write();
    const unsigned long code = writer->GetErrorCode();
    if (written != 1 || code != vtkErrorCode::NoError)
      throw writeFailure(path, std::string("VTK's writer failed (") + vtkErrorCode::GetStringFromErrorCode(code) + ")");
  };
  if (extension == ".vtp") {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetDataModeToAppended();
    // NB: raw bytes after the XML header, not base64 text (VTK's default):
    // a third smaller, and the encoding was a fifth of the writing time of a
    // fitted kitten's 15 MB surface. VTK's and ParaView's readers (and so
    // Slicer's) read both.
    writer->EncodeAppendedDataOff();
    // NB: LZ4, not zlib: on the caudate demo's 24 578-point surface zlib (at
    // its fastest level) took 42 ms, the longest step of writing a
    // segmentation's outputs, and LZ4 0.5 ms more than no compression (5.6
    // ms), for a file of 2.0 MB instead of 1.5 (2.4 uncompressed). VTK reads
    // it from 8.1 on (ParaView 5.5, 3D Slicer 4.10).
    vtkNew<vtkLZ4DataCompressor> compressor;
    writer->SetCompressor(compressor);
    writer->SetFileName(output.temporaryPath().c_str());
    write(writer.GetPointer());
  } else {
    const auto writer =
        vtkSmartPointer<vtkWriter>::Take(geometryformats::functions().newWriter(extension, output.temporaryPath()));
    write(writer.GetPointer());
  }
  output.commit();
}

}  // namespace dynsub
