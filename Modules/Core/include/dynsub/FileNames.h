#pragma once
// Small helpers on file names shared by the readers and writers.
#include <string>

namespace dynsub {

// The extension of `path` with its dot, in lower case ("Mesh.OBJ" -> ".obj").
std::string lowerCaseExtension(const std::string& path);

}  // namespace dynsub
