// Internal: what a glTF stores compactly, read as plain data and written back compact wherever it
// did not change.
//  - decode_meshopt: buffer views compressed by EXT_meshopt_compression (attributes, triangles,
//    indices; the octahedral, quaternion and exponential filters) decoded through
//    meshoptimizer into GltfDocument::decoded_views; the JSON is left as it is, so what the
//    writer does not change stays compressed.
//  - decode_draco: primitives compressed by KHR_draco_mesh_compression decoded through Draco into
//    GltfDocument::decoded_accessors (Draco's point count is the truth); on writing,
//    uncompress_changed_draco gives the accessors of each primitive whose attributes the writer
//    re-pointed buffer views of their own and drops the extension from it (the extension stays
//    in extensionsUsed while a primitive keeps it).
//  - EXT_mesh_gpu_instancing: instance_matrices gives a node's instance transforms (each drawn
//    as a drawing of its own); on writing, draw_instances keeps the extension where every
//    instance still draws one mesh, else turns the node into the parent of one child node per
//    instance, each drawing its own mesh.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "gltf_document.h"

namespace specdeform::detail {

void decode_meshopt(GltfDocument& doc);
void decode_draco(GltfDocument& doc);
// `original`: the JSON as read. Returns a note when it uncompressed a primitive.
std::vector<std::string> uncompress_changed_draco(GltfDocument& doc, const Json& original);

// Node `node`'s instances, each translation * rotation * scale; empty for a node without them.
std::vector<Eigen::Matrix4d> instance_matrices(const GltfDocument& doc, int node);
// Node `node`'s instances drawing `meshes` (one per instance, in order); true where it became a
// parent of one node per instance.
bool draw_instances(GltfDocument& doc, int node, const std::vector<int>& meshes);

}  // namespace specdeform::detail
