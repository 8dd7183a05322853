// Feeds arbitrary bytes to every mesh reader: each must return a valid mesh or throw InputError
// of one line.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  // The first byte picks the format, the rest is the file.
  const specdeform::MeshFormat formats[] = {
      specdeform::MeshFormat::Obj, specdeform::MeshFormat::Off, specdeform::MeshFormat::Ply,
      specdeform::MeshFormat::Stl};
  const auto format = formats[data[0] % 4];
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    const specdeform::LoadedMesh m = specdeform::read_mesh_from_memory(bytes, format, "fuzz");
    const int n = m.mesh.num_vertices();
    if (m.mesh.num_faces() == 0 || !m.mesh.V.allFinite() || m.mesh.F.minCoeff() < 0 ||
        m.mesh.F.maxCoeff() >= n || static_cast<int>(m.info.vertex_to_file.size()) != n) {
      std::abort();
    }
  } catch (const specdeform::InputError& e) {
    if (std::string_view(e.what()).find('\n') != std::string_view::npos) std::abort();
  }
  return 0;
}
