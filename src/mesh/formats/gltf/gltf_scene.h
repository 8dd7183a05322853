// Internal: where the default scene of a glTF document draws its meshes.
//
// The default scene is `scene`, else the first; without scenes, the nodes no node has as a child.
// A drawing is a mesh as one node draws it: its world matrix is the product of the node
// transforms (a `matrix`, or translation * rotation * scale) from the root down; a skinned mesh is
// drawn in its bind pose (the identity: glTF ignores its node's transform); a node with
// EXT_mesh_gpu_instancing draws one per instance (its transform after the node's). Drawings come
// mesh by mesh in the `meshes` order, a mesh's drawings in the order of their nodes' indices (and
// instances). Throws
// InputError for a scene that names a missing node or mesh, a node reached twice (glTF's nodes
// form trees) and a transform that is not invertible.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "gltf_document.h"

namespace specdeform::detail {

struct GltfDrawing {
  int mesh = -1, node = -1, instance = -1;  // instance: -1 for a node without instancing
  Eigen::Matrix4d world = Eigen::Matrix4d::Identity();  // mesh space -> world space
};

std::vector<GltfDrawing> scene_drawings(const GltfDocument& doc);

// A node's own transform.
Eigen::Matrix4d node_matrix(const Json& node);

}  // namespace specdeform::detail
