#include "appearance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace specdeform::server {

std::optional<Appearance> file_appearance(const LoadedMesh& loaded) {
  if (!loaded.file) return std::nullopt;
  const MeshFile& file = *loaded.file;
  const FileAttributes& a = file.attributes;
  const bool uv = !a.corner_uv.empty(), normals = !a.corner_normal.empty();
  const bool colours = a.colours.rows() > 0, materials = !a.materials.empty();
  if (!uv && !normals && !colours && !materials) return std::nullopt;
  const Faces& F = loaded.mesh.F;
  const std::vector<int> corner = triangle_corners(file, loaded.info, F);
  const uint32_t normal_rows = static_cast<uint32_t>(a.normals.rows());
  const bool turn_v = file.format == MeshFormat::Gltf || file.format == MeshFormat::Glb;
  const size_t M = a.materials.size();

  Appearance out;
  std::map<std::array<int, 3>, uint32_t> render;  // (mesh vertex, uv row, normal row)
  std::vector<uint32_t> render_corners(3 * size_t(F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int c = corner[3 * f + k];
      const int t = c >= 0 && uv ? a.corner_uv[c] : -1;
      const int n = c >= 0 && normals ? a.corner_normal[c] : -1;
      const auto [it, added] =
          render.emplace(std::array{F(f, k), t, n}, static_cast<uint32_t>(out.vertex.size()));
      render_corners[3 * f + k] = it->second;
      if (!added) continue;
      out.vertex.push_back(static_cast<uint32_t>(F(f, k)));
      out.normal_group.push_back(n >= 0 ? uint32_t(n) : normal_rows + uint32_t(F(f, k)));
      if (uv) {
        out.uv.push_back(t >= 0 ? float(a.uv(t, 0)) : 0.f);
        out.uv.push_back(t >= 0 ? float(turn_v ? 1.0 - a.uv(t, 1) : a.uv(t, 1)) : 0.f);
      }
      if (colours) {
        const int v = c >= 0 ? a.corners[c] : loaded.info.vertex_to_file[F(f, k)];
        for (int j = 0; j < 4; ++j) {
          out.rgba.push_back(
              static_cast<uint8_t>(std::lround(std::clamp(a.colours(v, j), 0.f, 1.f) * 255)));
        }
      }
    }
  }
  // Triangles by material, the ones without last.
  const auto material = [&](Eigen::Index f) {
    const int m = materials ? a.polygon_material[loaded.info.face_to_file[f]] : -1;
    return m < 0 ? M : size_t(m);
  };
  out.material_start.assign(M + 2, 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f) ++out.material_start[material(f) + 1];
  for (size_t m = 0; m <= M; ++m) out.material_start[m + 1] += out.material_start[m];
  std::vector<uint32_t> next(out.material_start.begin(), out.material_start.end() - 1);
  out.corners.resize(render_corners.size());
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const uint32_t at = next[material(f)]++;
    for (int k = 0; k < 3; ++k) out.corners[3 * at + k] = render_corners[3 * f + k];
  }
  for (size_t m = 0; m < M; ++m) {
    for (int k = 0; k < 4; ++k) out.base_color.push_back(a.materials[m].base_color[k]);
    out.textured.push_back(!a.materials[m].texture.empty() || a.materials[m].gltf_image >= 0);
    out.sampling.push_back(a.materials[m].sampling);
    if (turn_v) {  // the transform between turned coordinates: turn, transform, turn back
      Eigen::Matrix3f turn;
      turn << 1, 0, 0, 0, -1, 1, 0, 0, 1;
      Eigen::Matrix3f t = Eigen::Matrix3f::Identity();
      t.topRows<2>() = out.sampling.back().transform;
      out.sampling.back().transform = (turn * t * turn).topRows<2>();
    }
    out.unlit.push_back(a.materials[m].unlit);
  }
  return out;
}

}  // namespace specdeform::server
