#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "common.h"
#include "specdeform/mesh/mesh_info.h"

namespace specdeform::cli {

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "print a mesh's topology and geometry");
  struct Args {
    std::string path;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->path, "mesh file (.obj .off .ply .stl)")->required();
  cmd->add_flag("--json", args->json, "print one JSON object");
  cmd->callback([args] {
    const auto& [path, json] = *args;
    const LoadedMesh loaded = read_mesh(path);
    const MeshInfo i = compute_mesh_info(loaded.mesh);
    nlohmann::ordered_json j;
    j["file"] = path;
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
    j["unused_vertices"] = loaded.info.unused_vertices;
    j["collapsed_faces"] = loaded.info.collapsed_faces;
    j["file_vertices"] = loaded.info.file_vertices.rows();
    j["file_faces"] = loaded.info.file_faces;
    j["welded_corners"] = loaded.info.welded_corners;
    if (json) {
      std::cout << j.dump() << "\n";
      return;
    }
    for (const auto& [key, value] : j.items()) {
      std::cout << key << ": " << (value.is_string() ? value.get<std::string>() : value.dump())
                << "\n";
    }
  });
}

}  // namespace specdeform::cli
