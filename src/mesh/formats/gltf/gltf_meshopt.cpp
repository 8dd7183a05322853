// EXT_meshopt_compression decoded through Debian's meshoptimizer (gltf_decode.h).
#include <meshoptimizer.h>

#include "gltf_decode.h"

namespace specdeform::detail {

namespace {

constexpr const char* kMeshopt = "EXT_meshopt_compression";

}  // namespace

void decode_meshopt(GltfDocument& doc) {
  const Json& views = array_at(doc.json, "bufferViews");
  for (size_t v = 0; v < views.size(); ++v) {
    const Json& ext = object_at(object_at(views[v], "extensions"), kMeshopt);
    if (ext.empty()) continue;
    const std::string which = "buffer view " + std::to_string(v) + " (" + kMeshopt + ")";
    const int buffer = ext.value("buffer", -1);
    const size_t offset = ext.value("byteOffset", size_t(0)),
                 length = ext.value("byteLength", size_t(0));
    const size_t stride = ext.value("byteStride", size_t(0)), count = ext.value("count", size_t(0));
    const std::string mode = ext.value("mode", ""), filter = ext.value("filter", "NONE");
    if (buffer < 0 || size_t(buffer) >= doc.buffers.size() ||
        doc.buffers[buffer].source == GltfBufferSource::None ||
        offset > doc.buffers[buffer].bytes.size() ||
        length > doc.buffers[buffer].bytes.size() - offset) {
      doc.fail(which + " reaches beyond its buffer");
    }
    if (stride == 0 || stride > 256 || count > (size_t(1) << 31) / stride) {
      doc.fail(which + " has a bad byteStride or count");
    }
    const auto* source =
        reinterpret_cast<const unsigned char*>(doc.buffers[buffer].bytes.data() + offset);
    std::string out(count * stride, '\0');
    int status = -1;
    if (mode == "ATTRIBUTES") {
      if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" &&
          filter != "EXPONENTIAL") {
        doc.fail(which + ": unknown filter '" + filter + "'");
      }
      if (stride % 4 != 0) doc.fail(which + ": a byteStride not a multiple of 4");
      status = meshopt_decodeVertexBuffer(out.data(), count, stride, source, length);
      if (status == 0 && filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), count, stride);
      if (status == 0 && filter == "QUATERNION")
        meshopt_decodeFilterQuat(out.data(), count, stride);
      if (status == 0 && filter == "EXPONENTIAL")
        meshopt_decodeFilterExp(out.data(), count, stride);
    } else if (mode == "TRIANGLES" || mode == "INDICES") {
      if (stride != 2 && stride != 4) {
        doc.fail(which + ": indices of " + std::to_string(stride) + " bytes");
      }
      status = mode == "TRIANGLES"
                   ? meshopt_decodeIndexBuffer(out.data(), count, stride, source, length)
                   : meshopt_decodeIndexSequence(out.data(), count, stride, source, length);
    } else {
      doc.fail(which + ": unknown mode '" + mode + "'");
    }
    if (status != 0) {
      doc.fail(which + " could not be decoded (meshoptimizer error " + std::to_string(status) +
               ")");
    }
    doc.decoded_views[int(v)] = std::move(out);
  }
}

}  // namespace specdeform::detail
