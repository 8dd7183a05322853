// Internal: where a kept file's positions and normals sit in its bytes, per format, as its reader
// found them; the same-format rewriters (formats/*/*_rewriter.cpp) put new values there.
#pragma once

#include <string>
#include <variant>

#include "formats/gltf/gltf.h"
#include "formats/obj/obj.h"
#include "formats/off/off.h"
#include "formats/ply/ply.h"
#include "formats/stl/stl.h"

namespace specdeform::detail {

struct FileLayout {
  std::string bytes;  // the file as read (glTF: see GltfLayout)
  std::variant<ObjLayout, OffLayout, PlyLayout, StlLayout, GltfLayout> format;
};

}  // namespace specdeform::detail
