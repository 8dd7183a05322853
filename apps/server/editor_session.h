// What the browser editor edits: one mesh, its basis, a SpectralDeformer, the current selection
// and handle transforms. Messages in, messages out (protocol.h), no networking; the server runs
// it on one worker thread.
//
// Text messages (JSON objects with a "type"):
//   browser -> server
//     {"type": "hello"}                         resend the mesh and its state (a new connection)
//     {"type": "settings", "modes": m, "energy": "linear|arap", "ks": x, "kb": x,
//      "detail": "none|displacement|frames|transfer", "constraints": "soft|hard",
//      "view": "detailed|base"}   any subset
//     {"type": "open_demo"}                     the built-in bumpy bar
//     {"type": "export_mesh", "format": "obj|off|ply|stl"}   answered with a file message
//     {"type": "export_scene"}                  the scene JSON of `specdeform deform --scene`
//   server -> browser
//     {"type": "progress", "stage": s, "fraction": f}
//     {"type": "ready", "name", "vertices", "faces", "diagonal", "modes", "settings",
//      "basis": {"seconds", "source": "computed|cache", "residual"}, "setup": {...}}
//     {"type": "selection", "handles": [sizes], "fixed": k, "seconds": s}
//     {"type": "error", "message": one line}
// A bad message is answered with an error and changes nothing.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/io.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::server {

// Solver settings of the editor: the library's, but frames with the basis in single precision
// (twice as fast an inverse transform; a displacement error of about 1e-7 of itself), and ARAP
// starting from the previous frame (a drag moves the handle a little per frame).
inline DeformOptions editor_deform_options() {
  DeformOptions o;
  o.float32_basis = true;
  o.arap.warm_start = true;
  return o;
}

struct EditorConfig {
  int modes = 100;                                  // m of a newly opened mesh
  DeformOptions options = editor_deform_options();  // solver settings of a newly opened mesh
  std::filesystem::path cache_dir;                  // basis cache; empty: none
};

// Thrown from a progress report after cancel(): the computation is abandoned.
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
};

// The built-in model the editor opens without a mesh (and on "open_demo"): the bumpy bar.
inline constexpr const char* kDemoName = "bumpy-bar.obj";
LoadedMesh demo_mesh();

class EditorSession {
 public:
  // `send(binary, data)` delivers one message to the browser.
  using Send = std::function<void(bool binary, std::string data)>;

  EditorSession(EditorConfig config, Send send);
  ~EditorSession();

  // Computes (or loads) the basis and builds the deformer, then announces the mesh. Throws
  // InputError or SolverError, keeping the previous mesh, if that fails.
  void open(LoadedMesh mesh, std::string name);

  // Handles one message; errors are answered with an error message, never thrown.
  void handle(bool binary, std::string_view message);

  // Abandons a running basis computation at its next progress report (from any thread).
  void cancel() { cancelled_ = true; }

 private:
  struct State;
  void dispatch(bool binary, std::string_view message);
  void text_message(std::string_view message);
  void set_selection(Selection selection);
  void solve_and_send();
  void send_state();
  void build(LoadedMesh mesh, std::string name, int modes, const DeformOptions& options,
             std::shared_ptr<const ManifoldHarmonics> reuse_basis);
  void send_error(const std::string& message);

  EditorConfig config_;
  Send send_;
  std::atomic<bool> cancelled_{false};
  std::unique_ptr<State> state_;
};

}  // namespace specdeform::server
