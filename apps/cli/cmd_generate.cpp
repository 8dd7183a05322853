#include <iostream>
#include <map>
#include <memory>

#include "common.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"

namespace specdeform::cli {

void add_generate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "generate",
      "write a procedural mesh: bumpy-bar, bumpy-tube, bumpy-plane, icosphere or torus");
  struct Args {
    std::string shape, output;
    BumpyBarOptions bar;
    BumpyTubeOptions tube;
    BumpyPlaneOptions plane;
    double length = 0.0;
    int subdivisions = 5;
    int resolution = 0;
    double bump_height = -1.0;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("SHAPE", args->shape, "bumpy-bar | bumpy-tube | bumpy-plane | icosphere | torus")
      ->required()
      ->check(CLI::IsMember({"bumpy-bar", "bumpy-tube", "bumpy-plane", "icosphere", "torus"}));
  cmd->add_option("-o,--output", args->output, "mesh file to write")->required();
  cmd->add_option("--resolution", args->resolution,
                  "cells per unit length (bar and tube, default 24), cells per side (plane, "
                  "default 64), major segments (torus, default 96)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--subdivisions", args->subdivisions, "icosphere refinement levels (default 5)")
      ->check(CLI::Range(0, 9));
  cmd->add_option("--bump-height", args->bump_height, "height of the bumps (bar, tube, plane)")
      ->check(kNonNegative);
  cmd->add_option("--length", args->length, "bar length (default 4) or tube length (default 6)")
      ->check(kPositive);
  cmd->callback([args] {
    check_mesh_output(args->output);
    TriangleMesh mesh;
    const std::string& shape = args->shape;
    if (shape == "bumpy-bar") {
      BumpyBarOptions o = args->bar;
      if (args->resolution > 0) o.cells_per_unit = args->resolution;
      if (args->bump_height >= 0) o.bump_height = args->bump_height;
      if (args->length > 0) o.length = args->length;
      mesh = make_bumpy_bar(o);
    } else if (shape == "bumpy-tube") {
      BumpyTubeOptions o = args->tube;
      if (args->resolution > 0) o.cells_per_unit = args->resolution;
      if (args->bump_height >= 0) o.bump_height = args->bump_height;
      if (args->length > 0) o.length = args->length;
      mesh = make_bumpy_tube(o);
    } else if (shape == "bumpy-plane") {
      BumpyPlaneOptions o = args->plane;
      if (args->resolution > 0) o.resolution = args->resolution;
      if (args->bump_height >= 0) o.bump_height = args->bump_height;
      mesh = make_bumpy_plane(o);
    } else if (shape == "icosphere") {
      mesh = make_icosphere(args->subdivisions);
    } else {
      const int major = args->resolution > 0 ? args->resolution : 96;
      mesh = make_torus(1.0, 0.35, major, std::max(3, major / 3));
    }
    write_mesh(args->output, mesh);
    std::cout << "wrote " << args->output << " (" << mesh.num_vertices() << " vertices, "
              << mesh.num_faces() << " faces)\n";
  });
}

}  // namespace specdeform::cli
