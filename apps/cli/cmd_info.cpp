#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "common.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::cli {

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "print a mesh's topology, geometry and defects");
  struct Args {
    std::string path, cache;
    bool json = false, basis = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->path, "mesh file (.obj .off .ply .stl .gltf .glb)")->required();
  cmd->add_flag("--json", args->json, "print one JSON object");
  cmd->add_flag("--basis", args->basis,
                "compute the basis deform would (default options), as deform's last check");
  cmd->add_option("--basis-cache", args->cache,
                  "with --basis: a basis cache file, read if it matches, written otherwise");
  cmd->callback([args] {
    const auto& [path, cache, json, check_basis] = *args;
    const MeshFileReport report = inspect_mesh_file(path);
    const FileSummary& contents = report.contents;
    nlohmann::ordered_json j;
    j["file"] = path;
    j["format"] = contents.format;
    const auto text = [](const nlohmann::ordered_json& v) {
      return v.is_string() ? v.get<std::string>() : json_text(v);
    };
    const auto print = [&] {
      if (json) {
        std::cout << text(j) << "\n";
        return;
      }
      for (const auto& [key, value] : j.items()) {
        if (!value.is_null()) std::cout << key << ": " << text(value) << "\n";
      }
    };
    const auto gltf = [&] {
      return nlohmann::ordered_json{{"nodes", contents.nodes},
                                    {"meshes", contents.meshes},
                                    {"drawings", contents.drawings},
                                    {"primitives", contents.primitives},
                                    {"skins", contents.skins},
                                    {"animations", contents.animations},
                                    {"morph_targets", contents.morph_targets},
                                    {"images", contents.images},
                                    {"extensions", contents.extensions}};
    };
    if (!report.loaded) {  // what the file holds, and why deform would refuse it
      j["materials"] = contents.materials;
      j["gltf"] = gltf();
      j["deform"] = {{"ok", false}, {"refused", report.refused}};
      print();
      return;
    }
    const LoadedMesh& loaded = *report.loaded;
    const MeshInfo i = compute_mesh_info(loaded.mesh);
    j["vertices"] = i.vertices;
    j["faces"] = i.faces;
    j["edges"] = i.edges;
    j["components"] = i.components;
    j["boundary_loops"] = i.boundary_loops;
    j["boundary_edges"] = i.boundary_edges;
    j["euler_characteristic"] = i.euler_characteristic;
    j["area"] = i.area;
    j["bbox_min"] = {i.bbox_min.x(), i.bbox_min.y(), i.bbox_min.z()};
    j["bbox_max"] = {i.bbox_max.x(), i.bbox_max.y(), i.bbox_max.z()};
    j["bbox_diagonal"] = i.bbox_diagonal;
    j["non_manifold_edges"] = i.non_manifold_edges;
    j["degenerate_faces"] = i.degenerate_faces;
    j["duplicate_faces"] = loaded.info.duplicate_faces + i.duplicate_faces;  // dropped on reading
    // Defects, their first vertex in the file's numbering (null: none).
    const auto file_vertex = [&](int v) {
      return v < 0 ? nlohmann::ordered_json()
                   : nlohmann::ordered_json(loaded.info.vertex_to_file[v]);
    };
    j["zero_area_vertices"] = i.zero_area_vertices;
    j["first_zero_area_vertex"] = file_vertex(i.first_zero_area_vertex);
    j["pinch_vertices"] = i.pinch_vertices;
    j["first_pinch_vertex"] = file_vertex(i.first_pinch_vertex);
    j["inconsistent_edges"] = i.inconsistent_edges;
    j["misoriented_components"] = i.misoriented_components;
    j["first_inconsistent_edge"] =
        i.inconsistent_edges == 0
            ? nlohmann::ordered_json()
            : nlohmann::ordered_json({file_vertex(i.first_inconsistent_edge[0]),
                                      file_vertex(i.first_inconsistent_edge[1])});
    j["coincident_vertices"] = i.coincident_vertices;
    j["first_coincident_vertices"] =
        i.coincident_vertices == 0
            ? nlohmann::ordered_json()
            : nlohmann::ordered_json({file_vertex(i.first_coincident_vertices[0]),
                                      file_vertex(i.first_coincident_vertices[1])});
    j["unused_vertices"] = loaded.info.unused_vertices;
    j["collapsed_faces"] = loaded.info.collapsed_faces;
    j["file_vertices"] = loaded.info.file_vertices.rows();
    j["file_faces"] = loaded.info.file_faces;
    j["welded_corners"] = loaded.info.welded_corners;
    j["welded_vertices"] = loaded.info.welded_vertices;
    // What the file holds besides positions, and what a round trip keeps.
    nlohmann::ordered_json polygons = nlohmann::ordered_json::object();
    for (const auto& [corners, count] : contents.polygon_sizes)
      polygons[std::to_string(corners)] = count;
    j["polygons_by_corners"] = polygons;
    j["texture_coordinates"] = contents.texture_coordinates;
    j["uv_sets"] = contents.uv_sets;
    j["normals"] = contents.normals;
    j["vertex_colours"] = contents.vertex_colours;
    j["materials"] = contents.materials;
    j["groups"] = contents.groups;
    if (loaded.file->format == MeshFormat::Gltf || loaded.file->format == MeshFormat::Glb) {
      j["gltf"] = gltf();
    }
    if (!contents.properties.empty()) j["properties"] = contents.properties;
    j["round_trip_keeps"] = contents.round_trip;
    // deform's checks of the mesh before any selection: its operators (mollified where it needs
    // it) finite with an area at every vertex; with --basis, the basis itself.
    nlohmann::ordered_json deform = {{"ok", true}};
    std::string refused;
    try {
      const LaplacianOperators L =
          laplacian_operators(loaded.mesh, MassType::Lumped, LaplacianType::Cotan);
      check_operators(L.stiffness, L.mass, "the Laplacian");
    } catch (const Error& e) {
      refused = e.what();
      deform = {{"ok", false}, {"refused", refused}};
    }
    if (!contents.changes.empty()) deform["writing_changes"] = contents.changes;
    const int modes = default_modes(loaded.mesh.num_vertices());
    if (modes < ManifoldHarmonicsOptions{}.num_modes) deform["default_modes"] = modes;
    deform["checked"] = check_basis ? "the mesh, its operators and the basis"
                                    : "the mesh and its operators (--basis: the basis too)";
    if (check_basis && refused.empty()) {
      ManifoldHarmonicsOptions h;
      h.num_modes = modes;
      h.solver = default_eigensolver(loaded.mesh.num_vertices(), h.policy);
      try {
        const auto basis = obtain_basis(loaded.mesh, h, cache);
        deform["basis"] = residual_summary(*basis);
      } catch (const Error& e) {
        deform["ok"] = false;
        deform["refused"] = e.what();
      }
    }
    j["deform"] = deform;
    print();
  });
}

}  // namespace specdeform::cli
