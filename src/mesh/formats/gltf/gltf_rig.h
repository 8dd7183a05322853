// Internal: a glTF's skins following a deformation of the meshes they drive (Joints::Follow,
// mesh_file.h; docs/files.md, "Rigs").
//
// Skinning space is the bind pose's world space (glTF draws a skinned mesh in its bind pose, its
// node's transform ignored: gltf_scene.h), so joint j's bind matrix is B_j = IBM_j^-1 and a
// skinned file vertex's position there is its world position.
//  1. Each joint's motion T_j (x -> R x + t, R a rotation): the rigid motion nearest, in the least
//     squares of the skin weights, to the map of the vertices it drives from rest to deformed
//     (weighted Procrustes). The weights, not the deformation carried inside the volume: they
//     are the file's own statement of what each joint moves, and the motion that keeps its
//     vertices' coordinates in the joint's frame is what makes the joint sit where its part now
//     is. T_j is exactly the identity where none of its vertices moved; a joint that drives no
//     vertex moves with its nearest joint ancestor; one whose vertices lie on a line takes its
//     ancestor's turn (theirs leaves the turn about the line open).
//  2. The bind pose follows: B'_j = T_j B_j, IBM'_j = IBM_j T_j^-1, so the skinned mesh at its
//     bind pose is exactly the deformed rest.
//  3. Each transform L of joint j (its node's rest transform, every key of its animation channels)
//     becomes K_j L, K_j = P'^-1 T_j P with P, P' the bind-pose world matrices of j's parent
//     before and after (a joint's B, B'; another node's, its parent's times its own transform).
//     The pose relative to the bind (L = L_bind D) is kept (L' = L'_bind D): an animated part
//     turns about its joint's new place, and its children ride on it. Left-multiplying by a
//     similarity K = (k_t, k_R, k_s) commutes with glTF's interpolation: a translation key v
//     becomes k_t + k_s k_R v, a rotation key q becomes k_R q, a scale key s becomes k_s s
//     (cubic-spline tangents alike, without k_t). A joint whose K is not a similarity (a parent
//     with shear or unequal scales) is left as it was, and said.
//  4. A mesh a joint carries without a skin (a hat, a sword) keeps its world transform at rest (its
//     positions were deformed where it is drawn): its transforms are left-multiplied by G'^-1 G,
//     G and G' its joint's rest world matrix before and after; it still rides on the joint.
// A skin that names a missing node or has fewer matrices than joints, and weights that are not
// one per vertex, are left as they are, and said. Joints with K = I keep their bytes; so do
// animations that key no changed joint. Accessors are written in place where they are float and
// used by nothing else, else as new ones.
#pragma once

#include <string>
#include <vector>

#include "gltf.h"

namespace specdeform::detail {

// `doc` (the layout's document being rewritten) with its skins following `positions` (one row
// per file vertex, world space; `rest` the file's). Returns the notes: how many joints followed,
// which animation channels changed, joints left as they were.
std::vector<std::string> follow_joints(GltfDocument& doc, const GltfLayout& layout,
                                       const Vertices& rest, const Vertices& positions);

// What a deform changes in the document's rig (`info`): its morph targets and skins, and the
// options that keep them.
std::vector<std::string> rig_changes(const GltfDocument& doc);

}  // namespace specdeform::detail
