// The files of an export as one download: a zip archive (libzip) holding each under its name,
// so that a .gltf with its buffer and images, or an OBJ with its MTL and images, works where it
// is unpacked.
#pragma once

#include <string>
#include <vector>

#include "specdeform/mesh/mesh_file.h"

namespace specdeform::server {

// The archive's bytes (stored names as given, relative, '/' separated). Throws InputError for a
// name that leaves the archive's folder (absolute, or with a ".." part).
std::string zip_archive(const std::vector<OutputFile>& files);

}  // namespace specdeform::server
