// The editor's WebSocket protocol: binary messages for everything sized by the mesh, JSON text
// messages for the rest. Pure encoding and decoding, no networking; the decoders validate every
// field and throw InputError with a one-line reason.
//
// Binary messages are little-endian, start with a u32 tag, and keep every array aligned to its
// element size, so the browser reads them with typed arrays in place.
//
// Browser -> server
//   1 selection    u32 tag | u32 groups G | u32 fixed F | u32 flags (bit 0: echo, answer with
//                  104 as well: a restored selection) | u32 size of each group (G) |
//                  u32 flags of each group (G; bit 0: pinned, bit 1: fit, see GroupSelection) |
//                  f64 4 x 4 row-major transform of each group (16 G) |
//                  u32 fixed vertices (F) | u32 vertices of group 0, 1, ... (mesh numbering)
//   2 frame        u32 tag | u32 seq | u32 groups G | u32 flags (bit 0: preview) |
//                  f64 4 x 4 row-major transform of each group (16 G), acting on the rest shape
//   3 mesh file    u32 tag | u32 name length L | name (L bytes, padded with zeros to 4) | file
//   4 selection    the same layout as 3, for a .sel or .dmat file (file numbering)
//   5 scene        the same layout as 3, for a scene (.json, docs/scene.md)
//   6 companion    the same layout as 3: a file the next mesh file names (an MTL, a texture, a
//                  .gltf's buffer), by that name; sent before the mesh file
// Server -> browser
//   101 mesh part  u32 tag | u32 n | u32 triangles T | u32 kind (0: positions, 1: triangles) |
//                  u32 first vertex or triangle | u32 count C | f32 positions (3 C) or u32
//                  corners (3 C): the mesh in parts of at most kMeshPartItems, its positions
//                  first, so that the page counts the bytes and draws the triangles as they
//                  come; a mesh being opened is sent before its basis is computed. The
//                  server gathers the parts and the page fetches them over HTTP
//                  (editor_server.h), not over the socket
//   102 frame      u32 tag | u32 seq | u32 n | u32 view (bit 0: smooth base, bit 1: preview,
//                  bit 2: the smooth base folded, details added as displacements there,
//                  bit 3: at rest, no displacements follow: 4 MB less at 692k) |
//                  f32 reduced solve, inverse transform, detail, total (ms) |
//                  f32 the smooth base's miss of its targets, max, rms (over the bounding-box
//                  diagonal: SpectralDeformer::base_miss) |
//                  u32 ARAP iterations | u32 1 if ARAP converged (or the energy is linear) |
//                  f32 scale | i16 displacements (3 n, then zeros to a multiple of 4 bytes):
//                  position = rest position + scale * displacement, of all vertices or of the
//                  preview's, in its order (half the size of float32 positions; the step is
//                  the largest displacement / 32767)
//   103 file       the layout of 3: an export for the browser to save
//   104 selection  the layout of 1 (no fit flags): the server's selection and transforms, for
//                  the browser to adopt (after a reload, an undo, a selection file or a scene)
//   105 preview    u32 tag | u32 k | u32 triangles T | u32 mesh vertex of each preview vertex
//                  (k) | u32 corners (3 T, preview numbering): a coarse view for drags
//   106 appearance u32 tag | u32 render vertices R | u32 triangles T | u32 materials M |
//                  u32 flags (bit 0: uv, bit 1: colours) | u32 mesh vertex (R) |
//                  u32 normal group (R) | u32 corners (3 T, render numbering) |
//                  u32 first triangle of each material, then of "none", then T (M + 2) |
//                  f32 base colour RGBA (4 M) | u32 1 where the material has an image (M) |
//                  per material: u32 bit 0 unlit, bit 1 nearest, bits 2-3 and 4-5 wrap u and
//                  v (0 repeat, 1 clamp, 2 mirror) | f32 image transform, 2 rows of 3 (M x 7) |
//                  f32 uv (2 R, if bit 0) | u8 RGBA (4 R, if bit 1): the file's look
//                  (appearance.h), after the mesh message of a file that has one
//   107 texture    u32 tag | u32 material | u32 MIME type length L | MIME type (L bytes, padded
//                  with zeros to 4) | the image file's bytes
// Half a step (the largest displacement / 65534) is below the display's resolution and below
// 1e-5 of the bounding-box diagonal for displacements up to a third of it; exports are
// written by the server in double precision.
// Text (JSON objects with a "type"): see editor_session.h.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "appearance.h"
#include "specdeform/deform/selection.h"
#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::server {

enum class Tag : uint32_t {
  Selection = 1,
  Frame = 2,
  MeshFile = 3,
  SelectionFile = 4,
  SceneFile = 5,
  CompanionFile = 6,
  Mesh = 101,
  FrameResult = 102,
  File = 103,
  SelectionResult = 104,
  Preview = 105,
  Appearance = 106,
  Texture = 107,
};

// Limits that bound what a message can make the server allocate.
inline constexpr uint32_t kMaxGroups = 64;
inline constexpr uint32_t kMaxNameLength = 1024;

// Handle groups with their transforms and flags. A pinned group holds its vertices where they
// are shown: its transform is the one that best maps its rest positions to their current
// positions, fitted by the server when `fit` is set (a new or repainted pin), and frames do not
// move it.
struct GroupSelection {
  Selection selection;
  std::vector<Eigen::Affine3d> transforms;  // one per group
  std::vector<bool> pinned, fit;            // one per group
  bool echo = false;                        // the server sends it back (a restored edit)
};

struct FrameRequest {
  uint32_t seq = 0;
  std::vector<Eigen::Affine3d> transforms;  // one per handle group
  bool preview = false;                     // answer with the preview's vertices only
};

// A coarse version of the mesh drawn during drags: some of its vertices and triangles between
// them (preview.h).
struct PreviewMesh {
  std::vector<int> vertices;  // mesh vertex of each preview vertex
  Faces faces;                // preview numbering
};

// What a frame result shows.
struct FrameView {
  bool base = false;     // the deformed smooth base instead of the detailed result
  bool preview = false;  // only the preview's vertices
};

struct NamedFile {
  std::string name;
  std::string data;
};

struct FrameStats {
  double reduced_solve = 0, inverse_transform = 0, detail = 0, total = 0;  // seconds
  double error_max = 0, error_rms = 0;
  int arap_iterations = 0;
  bool arap_converged = true;
  int fold_zone = 0;  // faces where the details were added as displacements (a folded base)
};

// The tag of a binary message; throws InputError for one shorter than a tag.
Tag message_tag(std::string_view message);

// Throws InputError for a wrong length, too many groups, unknown flags, a transform
// checked_transform() refuses, or an index out of [0, n).
GroupSelection decode_selection(std::string_view message, int num_vertices);
// Throws InputError for a wrong length, a group count other than `num_groups`, or a transform
// checked_transform() (scene.h) refuses.
FrameRequest decode_frame(std::string_view message, int num_groups);
// Throws InputError for a wrong length or a name that is empty, too long or not printable.
NamedFile decode_file(std::string_view message);

std::string encode_selection(const GroupSelection& selection, Tag tag = Tag::SelectionResult);
std::string encode_frame(const FrameRequest& frame);
std::string encode_file(const NamedFile& file, Tag tag = Tag::File);
// The mesh's 101 messages, in order: positions [0, n), then triangles [0, T).
inline constexpr uint32_t kMeshPartItems = 1u << 16;
std::vector<std::string> encode_mesh_parts(const TriangleMesh& mesh,
                                           uint32_t part_items = kMeshPartItems);
// A 101 message's header; throws InputError if it is shorter than one.
struct MeshPartHeader {
  uint32_t n, triangles;
  uint32_t kind;  // 0: positions, 1: triangles
  uint32_t first, count;
};
MeshPartHeader mesh_part_header(std::string_view message);
// Whether a 101 message is a mesh's first part (its positions from vertex 0).
bool starts_mesh(std::string_view message);
std::string encode_preview(const PreviewMesh& preview);
std::string encode_appearance(const Appearance& appearance);
std::string encode_texture(uint32_t material, std::string_view mime, std::string_view image);
// `rest`: the whole mesh's; `positions`: the whole mesh's, or in a preview view those of
// `preview`'s vertices, in its order (InputError for another count).
std::string encode_frame_result(uint32_t seq, FrameView view, const FrameStats& stats,
                                const Vertices& positions, const Vertices& rest,
                                const PreviewMesh* preview = nullptr);
// The positions a frame result carries (the preview's vertices' for a preview), from the rest
// positions of the whole mesh. Throws InputError for a message of another length.
Vertices decode_frame_positions(std::string_view message, const Vertices& rest,
                                const PreviewMesh* preview = nullptr);

}  // namespace specdeform::server
