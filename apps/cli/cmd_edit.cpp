#include <cstdlib>
#include <iostream>
#include <memory>

#include "common.h"
#include "editor_server.h"

namespace specdeform::cli {

namespace {

std::filesystem::path default_cache_dir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg != '\0') {
    return std::filesystem::path(xdg) / "specdeform";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    return std::filesystem::path(home) / ".cache" / "specdeform";
  }
  return {};
}

// The editor's page: installed beside the program (`cmake --install`), else the web/dist of the
// source tree the program was built from.
std::string default_assets() {
  std::error_code error;
  const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::filesystem::path installed = program.parent_path() / SPECDEFORM_WEB_FROM_PROGRAM;
  if (!error && std::filesystem::exists(installed / "index.html", error)) {
    return installed.lexically_normal().string();
  }
  return SPECDEFORM_WEB_DIST;
}

}  // namespace

void add_edit_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("edit", "open the browser editor on a mesh (default: the demo)");
  struct Args {
    std::string mesh;
    server::ServerConfig server;
    server::EditorConfig editor;
    double max_upload_mb = 256;
    bool no_cache = false;
    EigenSolver eigensolver = EigenSolver::BlockKrylov;
    DeformArgs deform;
  };
  auto args = std::make_shared<Args>();
  args->server.assets = default_assets();
  args->editor.cache_dir = default_cache_dir();
  cmd->add_option("MESH", args->mesh, "mesh to open (default: the built-in bumpy bar)");
  cmd->add_option("--host", args->server.host,
                  "address to listen on (default 127.0.0.1: this machine only)");
  cmd->add_option("--port", args->server.port, "port (default 8080; 0: any free port)");
  cmd->add_option("-m,--modes", args->editor.modes, "manifold harmonics used (default 100)")
      ->check(CLI::Range(1, 5000));
  args->deform.add_to(*cmd);
  add_eigensolver_option(*cmd, args->eigensolver);
  cmd->add_option("--cache-dir", args->editor.cache_dir,
                  "where bases are cached (default ~/.cache/specdeform)");
  cmd->add_flag("--no-cache", args->no_cache, "neither read nor write cached bases");
  cmd->add_option("--max-upload-mb", args->max_upload_mb,
                  "largest mesh file the browser may send (default 256)")
      ->check(kPositive);
  cmd->add_option("--assets", args->server.assets,
                  "the built editor (default: the installed page, else web/dist)");
  cmd->callback([args, cmd] {
    args->editor.options = args->deform.merged(*cmd, server::editor_deform_options());
    args->editor.options.validate();
    if (args->no_cache) args->editor.cache_dir.clear();
    if (cmd->count("--eigensolver") > 0) args->editor.eigensolver = args->eigensolver;
    args->server.max_message_bytes = static_cast<size_t>(args->max_upload_mb * (1 << 20));
    server::EditorServer editor(args->server, args->editor);
    LoadedMesh mesh =
        args->mesh.empty() ? server::demo_mesh() : load_mesh(args->mesh, Confinement::Confined);
    const std::string name = args->mesh.empty()
                                 ? server::kDemoName
                                 : std::filesystem::path(args->mesh).filename().string();
    std::cerr << name << ": " << mesh.mesh.num_vertices()
              << " vertices; preparing m = " << args->editor.modes
              << " manifold harmonics (the page shows the progress)\n";
    editor.open_when_running(std::move(mesh), name);
    std::cout << "specdeform editor: " << editor.url() << "  (Ctrl-C stops it)" << std::endl;
    editor.run();
  });
}

}  // namespace specdeform::cli
