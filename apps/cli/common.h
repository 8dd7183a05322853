// Shared pieces of the command-line program: mesh loading with warnings, progress display,
// timing, and the registration functions of the subcommands.
#pragma once

#include <chrono>
#include <map>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "specdeform/deform/scene.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/mesh/io.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::cli {

// Accepts a finite number > 0, with a one-line reason otherwise.
extern const CLI::Validator kPositive;
// Accepts a number >= 0.
extern const CLI::Validator kNonNegative;

// The deformation settings' flags: --energy, --iterations, --arap-tolerance, --history,
// --clusters, --ks, --kb, --weight, --detail, --solver, --constraints. merged(): a scene's settings
// where no flag was given.
struct DeformArgs {
  DeformOptions options;
  void add_to(CLI::App& cmd);
  DeformOptions merged(const CLI::App& cmd, const DeformOptions& scene) const;
};

// Reads a mesh, keeping the file to write it back (LoadedMesh::file); what the reader dropped or
// merged is reported on stderr.
// `confinement`: which of the files it names may be read (the editor's server reads only those
// in its folder).
LoadedMesh load_mesh(const std::string& path, Confinement confinement = Confinement::Relative);
// The same without the file (LoadedMesh::file empty), for commands that write no copy of it:
// keeping a 692k-vertex OBJ took 0.6 s of its 1.6 s.
LoadedMesh load_geometry(const std::string& path);

// --normals follow|recompute|rotate: how the file's normals follow the new shape.
void add_write_options(CLI::App& cmd, WriteOptions& options);

// Writes positions V (one row per mesh vertex) as the loaded file with them (mesh_file.h), in
// the format of `path`'s extension; what it could not carry is said on stderr.
void write_result(const std::filesystem::path& path, const LoadedMesh& loaded, const Vertices& V,
                  const WriteOptions& options = {});

// A progress bar on stderr when it is a terminal; nothing otherwise.
ProgressCallback progress_bar(const std::string& label);

// JSON text for stdout or a file; bytes that are not UTF-8 (a file name) become U+FFFD, so the
// text stays valid JSON.
std::string json_text(const nlohmann::ordered_json& j, int indent = -1);
// A computation's profile as {"stage": seconds, ...} in the order the stages ran.
nlohmann::ordered_json stages_json(const std::vector<StageTime>& stages);

// Adds --eigensolver krylov|lanczos|multilevel to `cmd`, bound to `solver`.
void add_eigensolver_option(CLI::App& cmd, EigenSolver& solver);

// Adds --mass/--solver/--tolerance/... to `cmd`, bound to `options`.
void add_harmonics_options(CLI::App& cmd, ManifoldHarmonicsOptions& options);

// The library's obtain_basis (spectral/basis_store.h) with a progress bar, its warning and a
// note on a truncated cluster on stderr.
std::shared_ptr<const ManifoldHarmonics> obtain_basis(const TriangleMesh& mesh,
                                                      const ManifoldHarmonicsOptions& options,
                                                      const std::string& cache,
                                                      bool* loaded = nullptr);

// The handle options shared by deform and converge: --sel/--dmat with --def, or --scene.
// --json FILE and --markdown FILE: a table's rows as JSON and as markdown; write() also prints
// the markdown on stdout.
struct TableOutputs {
  std::string json, markdown;
  void add_to(CLI::App& cmd);
  void write(const nlohmann::ordered_json& rows, const std::string& table) const;
};

struct SceneArgs {
  std::string sel, def, dmat, scene;
  double influence = 0.0;  // --influence: the scene's region of influence (0: the scene's)
  void add_to(CLI::App& cmd);
};

// A mesh and its scene, read as the options say; the selection in the mesh's numbering, one
// transform per handle group. `mesh_path` may be empty when the scene names the mesh.
struct LoadedScene {
  LoadedMesh mesh;
  Scene scene;
  Selection selection;
  std::string name;  // the file the selection came from (the scene, .sel or .dmat)
};
LoadedScene load_scene(const std::string& mesh_path, const SceneArgs& args,
                       const DeformOptions& defaults);

// Refuses a mesh output that could not be written (its format unknown, its folder missing or
// not writable) before any work.
void check_mesh_output(const std::string& path);

// m for a mesh of `vertices` vertices: `requested` where the user asked for it (-m, a scene's
// "modes"), else the default, lowered to the mesh's vertices with a note on stderr.
int modes_for(int requested, bool asked, int vertices);

// Solves the same frame `repeat` times; the median of each stage's time, and the last result.
FrameTimings median_frame(SpectralDeformer& deformer,
                          const std::vector<Eigen::Affine3d>& transforms, int repeat,
                          Vertices* result = nullptr);

class Stopwatch {
 public:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

void add_info_command(CLI::App& app);
void add_basis_command(CLI::App& app);
void add_smooth_command(CLI::App& app);
void add_generate_command(CLI::App& app);
void add_subdivide_command(CLI::App& app);
void add_demo_command(CLI::App& app);
void add_deform_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_converge_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_edit_command(CLI::App& app);

}  // namespace specdeform::cli
