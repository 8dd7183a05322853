// The materials an OBJ's MTL files define (obj.h).
#include "mesh/file_layout.h"
#include "mesh/text_scanner.h"
#include "obj.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

// Kd and map_Kd of the materials the OBJ's MTL files define (texture names relative to the OBJ's
// folder); a missing MTL leaves the materials plain.
void read_obj_materials(MeshFile& file) {
  const ObjLayout& layout = std::get<ObjLayout>(file.layout->format);
  if (file.attributes.materials.empty() || !file.companions) return;
  for (const std::string& library : layout.mtllib) {
    std::optional<std::string> text;
    try {
      text = file.companions(library);
    } catch (const InputError&) {
      continue;  // a name the resolver refuses: plain materials
    }
    if (!text) continue;
    const std::filesystem::path folder = std::filesystem::path(library).parent_path();
    TextScanner in(*text, library);
    Material* current = nullptr;
    for (std::string_view key = in.next(); !key.empty(); key = in.next()) {
      if (key == "newmtl") {
        const std::string name(in.next());
        current = nullptr;
        for (Material& m : file.attributes.materials)
          if (m.name == name) current = &m;
      } else if (current && key == "Kd") {
        for (int k = 0; k < 3 && !in.at_line_end(); ++k) {
          const std::string_view t = in.next();
          double v = 1;
          std::from_chars(t.data(), t.data() + t.size(), v);
          current->base_color[k] = static_cast<float>(v);
        }
      } else if (current && key == "map_Kd") {
        std::string_view last;  // options (-s 1 1 1 ...) come first; the file name is last
        while (!in.at_line_end()) last = in.next();
        if (!last.empty()) current->texture = (folder / std::string(last)).generic_string();
      }
      in.skip_line();
    }
  }
}

}  // namespace specdeform::detail
