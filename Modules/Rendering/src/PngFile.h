#pragma once
// Private to the Rendering module: PNG files of captured windows, written
// here rather than by vtkPNGWriter. VTK's writer lets libpng try its five
// row filters on every row, which takes longer than rendering the 3D figure;
// here every row gets the "up" filter (the row above subtracted) and the
// data is deflated by libdeflate: the same pixels, in files about the size
// of VTK's at its default level, in a fraction of the time.
#include <string>

namespace dynsub {

// Writes `height` rows of `width` pixels of `channels` 8-bit samples (3: RGB,
// 4: RGBA) to `path` (a plain file, replaced). The rows are given bottom
// first, as VTK's images hold them; `dpi`, the pixels per inch the image is
// meant to be printed at, is recorded (the pHYs chunk, which viewers and
// layout programs read for the printed size). Throws dynsub::Error naming the path when
// the arguments are impossible or the file cannot be written.
void writePngFile(const std::string& path, int width, int height, int channels, const unsigned char* bottomRowFirst,
                  double dpi = 100.0);

}  // namespace dynsub
