#pragma once
// Small helpers on file names shared by the readers and writers.
#include <string>

namespace dynsub {

// The extension of `path` with its dot, in lower case ("Mesh.OBJ" -> ".obj").
std::string lowerCaseExtension(const std::string& path);

// Throws dynsub::Error naming `path` ("no such file or directory") unless it
// exists, as a file or a directory (a DICOM series).
void requireExisting(const std::string& path);

}  // namespace dynsub
