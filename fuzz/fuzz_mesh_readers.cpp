// Feeds arbitrary bytes to every mesh reader, glTF's included: each must return a valid mesh or
// throw InputError of one line. What is read is kept and written back: nothing moved, the same
// format gives the same bytes (an OBJ with line continuations excepted: they come back joined),
// and every other format writes without failing.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/io.h"

namespace sd = specdeform;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  // The first byte picks the format, the rest is the file.
  const sd::MeshFormat formats[] = {sd::MeshFormat::Obj, sd::MeshFormat::Off,  sd::MeshFormat::Ply,
                                    sd::MeshFormat::Stl, sd::MeshFormat::Gltf, sd::MeshFormat::Glb};
  const char* names[] = {"f.obj", "f.off", "f.ply", "f.stl", "f.gltf", "f.glb"};
  const int pick = data[0] % 6;
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    sd::ReadOptions options;
    options.keep_file = true;
    const sd::LoadedMesh m = sd::read_mesh_from_memory(bytes, formats[pick], "fuzz", options);
    const int n = m.mesh.num_vertices();
    if (m.mesh.num_faces() == 0 || !m.mesh.V.allFinite() || m.mesh.F.minCoeff() < 0 ||
        m.mesh.F.maxCoeff() >= n || static_cast<int>(m.info.vertex_to_file.size()) != n ||
        m.info.file_to_vertex.size() != static_cast<size_t>(m.info.file_vertices.rows())) {
      std::abort();
    }
    const sd::EncodedMesh same = sd::encode_mesh_file(*m.file, m.file->rest, names[pick]);
    const bool joined = pick == 0 && bytes.find('\\') != std::string_view::npos;
    if (!joined && same.files.front().bytes != bytes) std::abort();
    sd::encode_mesh_file(*m.file, m.file->rest, names[(pick + 1) % 6]);
  } catch (const sd::InputError& e) {
    if (std::string_view(e.what()).find('\n') != std::string_view::npos) std::abort();
  }
  return 0;
}
