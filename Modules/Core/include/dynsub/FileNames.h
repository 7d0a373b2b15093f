#pragma once
// Small helpers on file names shared by the readers and writers.
#include <fstream>
#include <string>

namespace dynsub {

// The extension of `path` with its dot, in lower case ("Mesh.OBJ" -> ".obj").
std::string lowerCaseExtension(const std::string& path);

// Throws dynsub::Error naming `path` ("no such file or directory") unless it
// exists, as a file or a directory (a DICOM series).
void requireExisting(const std::string& path);

// `path` opened for reading. Throws dynsub::Error naming it when it does not
// exist, is a directory (which std::ifstream opens, and fails on only at the
// first read, with a message that names no file) or cannot be opened.
std::ifstream openForReading(const std::string& path, std::ios::openmode mode = std::ios::in);

// Throws dynsub::UsageError naming `output` when it is the file `input`
// names, by any path (a link, a relative name): writing the output would
// destroy that input. Empty names and files that do not exist pass.
void requireNotInput(const std::string& output, const std::string& input);

}  // namespace dynsub
