// Feeds arbitrary messages to the editor's session (a small mesh open): every message must be
// handled or answered with an error message, never a crash. The first byte picks binary or text.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "editor_session.h"
#include "protocol.h"
#include "specdeform/mesh/generate.h"

namespace sd = specdeform;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static sd::server::EditorSession* session = [] {
    auto* s = new sd::server::EditorSession({.modes = 10}, [](bool, std::string) {});
    sd::LoadedMesh mesh;
    mesh.mesh = sd::make_icosphere(1);
    mesh.info = sd::identity_read_info(mesh.mesh);
    s->open(std::move(mesh), "sphere.obj");
    return s;
  }();
  if (size == 0) return 0;
  const bool binary = data[0] & 1;
  const std::string_view message(reinterpret_cast<const char*>(data + 1), size - 1);
  // Opening meshes is the mesh readers' fuzzer's business, and slow: left out here.
  if (binary && message.size() >= 4 &&
      sd::server::message_tag(message) == sd::server::Tag::MeshFile)
    return 0;
  if (!binary && message.find("open_demo") != std::string_view::npos) return 0;
  session->handle(binary, message);
  return 0;
}
