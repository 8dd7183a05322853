// Feeds arbitrary bytes to the scene readers; the first byte picks the format (JSON, .sel, .dmat,
// .def). Each must return its result or throw InputError of one line. A JSON scene that reads must
// also read back, as encode_scene() writes it, to the same selection, transforms and settings.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "specdeform/deform/scene.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"

namespace sd = specdeform;

namespace {

constexpr int kFileVertices = 12;

// An icosahedron's file whose vertices 0 and 5 no face uses (the reader dropped them).
const sd::MeshReadInfo& mesh() {
  static const sd::MeshReadInfo info = [] {
    sd::MeshReadInfo i;
    i.file_vertices = sd::make_icosphere(0).V;
    for (int v = 0; v < kFileVertices; ++v) {
      const bool kept = v != 0 && v != 5;
      i.file_to_vertex.push_back(kept ? static_cast<int>(i.vertex_to_file.size()) : -1);
      if (kept) i.vertex_to_file.push_back(v);
    }
    return i;
  }();
  return info;
}

// The selection files a scene may name: h.sel and h.dmat; nothing else (no disk access).
std::string read_file(const std::filesystem::path& path) {
  if (path.filename() == "h.sel") return "# status\n0\n0\n1\n1\n1\n1\n1\n1\n1\n2\n2\n2\n";
  if (path.filename() == "h.dmat") return "1 12\n0\n0\n-1\n-1\n1\n1\n-1\n-1\n-1\n2\n2\n2\n";
  throw sd::InputError(path.string() + ": cannot open file");
}

// Errors are one line.
void one_line(const sd::InputError& e) {
  if (std::string_view(e.what()).find('\n') != std::string_view::npos) std::abort();
}

void round_trip(const sd::Scene& scene) {
  const sd::Scene back =
      sd::parse_scene(sd::encode_scene(scene), "fuzz/back.json", mesh(), {}, read_file);
  const auto a = sd::match_transforms(scene.selection, scene.transforms);
  const auto b = sd::match_transforms(back.selection, back.transforms);
  bool same = back.selection.handles == scene.selection.handles &&
              back.selection.fixed == scene.selection.fixed && back.modes == scene.modes &&
              back.options.energy == scene.options.energy &&
              back.options.arap.clusters == scene.options.arap.clusters &&
              back.options.unconstrained == scene.options.unconstrained;
  for (size_t g = 0; same && g < a.size(); ++g) same = a[g].matrix() == b[g].matrix();
  if (!same) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  sd::Scene scene;
  try {
    switch (data[0] % 4) {
      case 0:
        scene = sd::parse_scene(text, "fuzz/scene.json", mesh(), {}, read_file);
        break;
      case 1:
        sd::parse_sel(text, kFileVertices, "fuzz.sel");
        return 0;
      case 2:
        sd::parse_dmat(text, kFileVertices, "fuzz.dmat");
        return 0;
      default:
        sd::parse_def(text, "fuzz.def");
        return 0;
    }
  } catch (const sd::InputError& e) {
    one_line(e);
    return 0;
  }
  round_trip(scene);  // outside the try: a scene that read must read back
  try {
    std::vector<std::string> notes;
    sd::to_mesh_numbering(scene.selection, mesh(), &notes, "fuzz");
  } catch (const sd::InputError& e) {
    one_line(e);
  }
  return 0;
}
