// The editor's HTTP and WebSocket server (Boost.Beast): serves the built browser editor and
// connects it to an EditorSession.
//
// - Binds to 127.0.0.1 unless told otherwise; answers only requests whose Host names the
//   server (no DNS rebinding) and WebSocket upgrades whose Origin is the server's own page.
// - Serves exactly the files found under the assets folder at start-up, read into memory, and
//   nothing else (no path traversal, no symbolic links followed); and the open mesh's parts
//   (protocol.h, 101) at /mesh/ID, which the socket's {"type": "mesh", "id", "bytes"} names,
//   and at /mesh/latest (its id in X-Mesh-Id) for a page that starts: a browser takes 25 MB
//   several times faster over HTTP than over a WebSocket, and while it makes its view.
// - One editor window at a time: a new connection takes over and the previous one is closed.
// - A "cancel" message is acted on as it arrives (EditorSession::cancel), not queued; a window
//   that connects while the basis is computed gets the latest progress at once.
// - Incoming messages run on one worker thread through a Mailbox (frames coalesce, latest
//   wins); outgoing frame results that have not started to go out are replaced by newer ones,
//   so neither direction lets the editor fall behind.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "editor_session.h"

namespace specdeform::server {

struct ServerConfig {
  std::string host = "127.0.0.1";
  uint16_t port = 8080;                   // 0: any free port
  std::filesystem::path assets;           // the built editor (web/dist)
  size_t max_message_bytes = 256u << 20;  // largest upload (a mesh file)
};

class EditorServer {
 public:
  // Reads the assets and binds the port; throws InputError if either fails.
  EditorServer(ServerConfig config, EditorConfig editor);
  ~EditorServer();

  // The session the browser talks to. Open its first mesh here before run(); from run() on it
  // belongs to the server's worker thread.
  EditorSession& session();

  // Opens the first mesh on the worker thread once run() starts, so that the page is served
  // (and shows the basis's progress) while it is prepared; a failure is reported to the page
  // and on stderr, and the page offers to open another mesh.
  void open_when_running(LoadedMesh mesh, std::string name);

  uint16_t port() const;
  std::string url() const;

  // Serves until stop() or SIGINT / SIGTERM.
  void run();
  // From any thread.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace specdeform::server
