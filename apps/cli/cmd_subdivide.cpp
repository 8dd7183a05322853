#include <iostream>
#include <map>
#include <memory>

#include "common.h"
#include "specdeform/mesh/subdivide.h"

namespace specdeform::cli {

void add_subdivide_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("subdivide", "refine a mesh by 1-to-4 splits (Loop or midpoint)");
  struct Args {
    std::string mesh, output;
    int levels = 1;
    SubdivisionScheme scheme = SubdivisionScheme::Loop;
  };
  auto args = std::make_shared<Args>();
  static const std::map<std::string, SubdivisionScheme> kSchemes{
      {"loop", SubdivisionScheme::Loop}, {"midpoint", SubdivisionScheme::Midpoint}};
  cmd->add_option("MESH", args->mesh, "mesh file")->required();
  cmd->add_option("-o,--output", args->output, "mesh file to write")->required();
  cmd->add_option("-l,--levels", args->levels, "number of 1-to-4 refinements (default 1)")
      ->check(CLI::Range(0, 6));
  cmd->add_option("--scheme", args->scheme, "loop (default) or midpoint")
      ->transform(CLI::CheckedTransformer(kSchemes, CLI::ignore_case));
  cmd->callback([args] {
    check_mesh_output(args->output);
    const LoadedMesh loaded = load_mesh(args->mesh);
    const TriangleMesh fine = subdivide(loaded.mesh, args->levels, args->scheme);
    write_mesh(args->output, fine);
    const std::vector<std::string> lost = contents_beyond_triangles(*loaded.file);
    if (!lost.empty()) {
      std::cerr << args->output
                << ": note: subdividing writes positions and triangles only; dropped:";
      for (size_t i = 0; i < lost.size(); ++i) std::cerr << (i ? ", " : " ") << lost[i];
      std::cerr << "\n";
    }
    std::cout << "wrote " << args->output << " (" << fine.num_vertices() << " vertices, "
              << fine.num_faces() << " faces)\n";
  });
}

}  // namespace specdeform::cli
