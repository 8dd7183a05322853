// What the browser editor edits: one mesh, its basis, a SpectralDeformer, the handle groups with
// their transforms, the poses applied and the history of edits. Messages in, messages out
// (protocol.h), no networking; the server runs it on one worker thread. The session is the one
// copy of the edit: a browser that connects (a reload, a second window) gets all of it back.
//
// Text messages (JSON objects with a "type"):
//   browser -> server
//     {"type": "hello"}              everything again (the server's own, for each connection;
//                                    "has_mesh": true when the connection got the mesh being
//                                    prepared: all but the mesh)
//     {"type": "settings", "modes": m, "energy": "linear|arap", "ks": x, "kb": x,
//      "detail": "none|displacement|frames|transfer", "constraints": "soft|hard",
//      "unconstrained": "follow|keep|error", "influence": r (of the diagonal, 0: none),
//      "view": "detailed|base"}
//                                    any subset; answered with "ready" (also when rejected)
//     {"type": "open_demo"}          the built-in bumpy bar
//     {"type": "commit"}             the transforms as they are now become an undo step
//     {"type": "undo"}, {"type": "redo"}
//     {"type": "apply_pose"}         the shown result becomes the rest shape (pins become fixed)
//     {"type": "preview", "vertices": k}   a coarse mesh for drags (preview.h)
//     {"type": "export_mesh", "format": "obj|off|ply|stl|gltf|glb",
//      "morph_targets": "turn|keep", "joints": "follow|keep"}   answered with one file
//                                    message: the mesh, or a .zip of it with every file it names
//                                    (a .gltf's buffers and images, an MTL and its images); without
//                                    "format", the opened file's own, everything in it kept
//     {"type": "export_scene"}       the scene JSON of `specdeform deform --scene`
//     {"type": "cancel"}             handled by the server at once: see cancel()
//   server -> browser
//     {"type": "progress", "stage": s, "fraction": f, "cancellable": b}
//                                    while a basis is prepared (after the mesh message of a mesh
//                                    being opened: the page draws it and paints handles
//                                    meanwhile, and sends the selection after "ready"); fraction 1
//                                    for a stage that has none ("setting up the solver")
//     {"type": "saving", "file", "done": false}, then {"type": "saving", "file", "done": true,
//      "seconds", "bytes" (when saved), "error" ("" when saved)}
//                                    a computed basis written to the cache in the background,
//                                    after "ready" (the last report again after the "ready" a
//                                    hello brings)
//     {"type": "ready", "name", "vertices", "faces", "diagonal", "mesh_id", "modes", "settings",
//      "pose", "basis": {"seconds", "source": "computed|cache|reused", "residual", "warning"},
//      "setup": {...}, "arap_clusters"}         after a mesh message or a settings request
//     {"type": "state", "request": the request's type ("open": the server's first mesh),
//      "groups": [{"vertices", "pinned", "transform": 16 numbers}], "fixed",
//      "undo", "redo", "selection_seconds", "pin_error", "free_pieces",
//      "constrained_piece_modes", "detail_pending", "pose"}
//                                               after every edit, last (its frame comes first);
//                                               request "detail": the transfer's background
//                                               factorisation became ready (its frame first)
//     {"type": "empty", "request"}              no mesh is open (a failed or cancelled start)
//     {"type": "note", "message": one line}     what an export dropped or changed
//     {"type": "error", "message": one line, "request": the request's type, "cancelled": b}
// Every request is answered: by its reply (ready, state, file, preview, a frame), or by an
// error naming the request, after which nothing has changed; a rejected setting is followed by
// "ready" with the settings in force.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "basis_store.h"
#include "protocol.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/io.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::server {

// Solver settings of the editor: the library's, but frames with the basis in single precision
// (twice as fast an inverse transform; a displacement error of about 1e-7 of itself), ARAP
// starting from the previous frame (a drag moves the handle a little per frame), and the
// transfer's factorisation in the background (displacements meanwhile; "state" says
// "detail_pending").
inline DeformOptions editor_deform_options() {
  DeformOptions o;
  o.float32_basis = true;
  o.background_transfer = true;  // a selection change waits for no factorisation
  o.arap.warm_start = true;
  return o;
}

struct EditorConfig {
  int modes = 100;                                  // m of a newly opened mesh
  DeformOptions options = editor_deform_options();  // solver settings of a newly opened mesh
  std::filesystem::path cache_dir;                  // basis cache; empty: none
  std::optional<EigenSolver> eigensolver;           // of the bases it computes; none: by size
                                                    // (default_eigensolver)
};

// Thrown from a progress report after cancel(): the computation is abandoned.
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
};

// The built-in model the editor opens without a mesh (and on "open_demo"): the bumpy bar.
inline constexpr const char* kDemoName = "bumpy-bar.obj";
LoadedMesh demo_mesh();

// The largest eigen-residual of a reused basis that "apply_pose" accepts (pose.h): beyond it
// the posed mesh's basis is computed.
inline constexpr double kReuseResidual = 1e-2;

class EditorSession {
 public:
  // `send(binary, data)` delivers one message to the browser; `post(job)` runs a job on the
  // session's thread later (from any thread): the transfer's background factorisation says
  // so when it is ready, and the session then sends the result with the transfer's details
  // (without `post`, that result comes with the next request).
  using Send = std::function<void(bool binary, std::string data)>;
  using Post = std::function<void(std::function<void()> job)>;

  EditorSession(EditorConfig config, Send send, Post post = {});
  ~EditorSession();

  // Sends the mesh, computes (or loads) the basis and builds the deformer, then announces the
  // mesh as ready. Throws InputError, SolverError or Cancelled, keeping the previous mesh (sent
  // again), if that fails.
  void open(LoadedMesh mesh, std::string name);

  // Handles one message; errors are answered with an error message, never thrown.
  void handle(bool binary, std::string_view message);

  // open(), with a failure answered as a request's is (an error message, then "empty" when no
  // mesh is open) and returned: the server's first mesh, opened while the page is served.
  std::optional<std::string> start(LoadedMesh mesh, std::string name);

  // Abandons a running basis computation at its next progress report (from any thread); the
  // request that started it is answered with a "cancelled" error. Does nothing when none runs.
  void cancel() {
    if (computing_) cancelled_ = true;
  }

 private:
  struct State;
  bool answer(const std::function<void()>& work);  // false: failed, answered with an error
  void dispatch(bool binary, std::string_view message);
  void text_message(std::string_view message);
  void change_settings(std::string_view message);
  // `record`: an undo step; `echo`: the selection is sent back (it did not come from the browser).
  void set_edit(GroupSelection edit, bool record, bool echo);
  void push_history();
  void commit();  // an undo step if the transforms moved since the last one
  void restore(size_t entry);
  void apply_pose();
  void open_scene(const NamedFile& file);
  // `preview`: solved without details and sent at the preview's vertices only.
  void solve_and_send(bool preview = false);
  // The detailed result of the current transforms, as shown; `final`: with the transfer's
  // details (waits for its background factorisation; exports and poses).
  const Vertices& result(bool final = false);
  void send_mesh();  // with the file's appearance and textures, if it has them
  void send_mesh(const TriangleMesh& rest, const std::optional<Appearance>& look,
                 const LoadedMesh& loaded);
  // The mesh (unless the connection has it), settings, selection and frame of the open edit, if
  // any.
  void resend_edit(bool mesh = true);
  void progress(std::string_view stage, double fraction, bool cancellable);
  // The basis just computed written to the cache on a thread of its own ("saving" messages).
  void save_in_background();
  void send_ready();
  void send_selection();
  void send_state();
  void send_error(const std::string& message, bool cancelled = false);
  void watch_detail();  // the deformer's background transfer calls detail_ready() via post_
  void detail_ready();
  // prepare_basis() with progress messages, abandoned by cancel().
  PreparedBasis compute_basis(const TriangleMesh& mesh, int modes);
  void build(LoadedMesh mesh, std::string name, int modes, const DeformOptions& options);

  EditorConfig config_;
  Send send_;
  Post post_;
  std::atomic<bool> computing_{false}, cancelled_{false};
  // Files the next mesh file names (companion messages), by name: given to its reader, then kept
  // with it for the textures the page asks for.
  std::shared_ptr<std::map<std::string, std::string>> companions_;
  std::string request_;     // the type of the message being handled
  std::string last_error_;  // of the last request that failed
  std::unique_ptr<State> state_;
  std::future<void> saving_;  // the basis being cached; last: waited for before the rest goes
  // The last "saving" report (done) of the open mesh's basis, said again to a page that comes
  // after it (a 43k basis is saved before a page has started); `opened_` counts the meshes
  // opened, so that a report of the one before is not kept.
  std::mutex saved_mutex_;
  std::string saved_;
  int opened_ = 0;
};

}  // namespace specdeform::server
