// glTF models built by the tests through tinygltf, as exporters write them: data appended to
// buffer 0 as buffer views and accessors, the model written as a .glb or an embedded .gltf.
#pragma once

#include <tiny_gltf.h>

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

namespace specdeform::test {

struct GltfModel {
  tinygltf::Model model;

  // `data` as a new buffer view (0: tightly packed); its index.
  template <typename T>
  int view(const std::vector<T>& data, int stride = 0) {
    std::vector<unsigned char>& b = model.buffers.at(0).data;
    while (b.size() % 4) b.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = b.size();
    v.byteLength = data.size() * sizeof(T);
    v.byteStride = stride;
    const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
    b.insert(b.end(), bytes, bytes + v.byteLength);
    model.bufferViews.push_back(v);
    return int(model.bufferViews.size()) - 1;
  }

  int accessor(int view, size_t offset, size_t count, int type, int component) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.byteOffset = offset;
    a.count = count;
    a.type = type;
    a.componentType = component;
    model.accessors.push_back(a);
    return int(model.accessors.size()) - 1;
  }

  std::string glb() const { return written(false, true); }
  std::string embedded() const { return written(true, false); }

 private:
  std::string written(bool embed_buffers, bool binary) const {
    std::ostringstream out;
    tinygltf::TinyGLTF writer;
    EXPECT_TRUE(writer.WriteGltfSceneToStream(&model, out, embed_buffers, binary));
    return out.str();
  }
};

}  // namespace specdeform::test
