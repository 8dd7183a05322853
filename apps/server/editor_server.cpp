#include "editor_server.h"

#include <utility>  // before Boost.Asio, whose awaitable.hpp uses std::exchange

#include <cstring>
#include <deque>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include <boost/asio.hpp>
#include <boost/beast.hpp>

#include "mailbox.h"
#include "protocol.h"
#include "specdeform/exceptions.h"

namespace specdeform::server {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;
using net::awaitable;
using net::use_awaitable;

namespace {

struct Asset {
  std::string body;
  std::string type;
};

std::string content_type(const std::filesystem::path& p) {
  static const std::map<std::string, std::string> types = {{".html", "text/html; charset=utf-8"},
                                                           {".js", "text/javascript"},
                                                           {".css", "text/css"},
                                                           {".svg", "image/svg+xml"},
                                                           {".png", "image/png"},
                                                           {".json", "application/json"},
                                                           {".ico", "image/x-icon"},
                                                           {".wasm", "application/wasm"}};
  const auto it = types.find(p.extension().string());
  return it == types.end() ? "application/octet-stream" : it->second;
}

// Every regular file under `dir` (symbolic links skipped), by URL path.
std::map<std::string, Asset> read_assets(const std::filesystem::path& dir) {
  if (!std::filesystem::is_regular_file(dir / "index.html")) {
    throw InputError(dir.string() +
                     ": the editor is not built (no index.html; scripts/setup.sh builds it)");
  }
  std::map<std::string, Asset> assets;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (entry.is_symlink() || !entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream body;
    body << in.rdbuf();
    const std::string url = "/" + entry.path().lexically_relative(dir).generic_string();
    assets[url] = {body.str(), content_type(entry.path())};
  }
  assets["/"] = assets.at("/index.html");
  return assets;
}

// One WebSocket connection; sends are posted to its strand from the worker thread.
class Connection : public std::enable_shared_from_this<Connection> {
 public:
  explicit Connection(websocket::stream<beast::tcp_stream> ws) : ws_(std::move(ws)) {}

  websocket::stream<beast::tcp_stream>& ws() { return ws_; }

  void send(bool binary, std::string data) {
    net::post(ws_.get_executor(),
              [self = shared_from_this(), binary, d = std::move(data)]() mutable {
                self->enqueue(binary, std::move(d));
              });
  }

  void close(const std::string& reason) {
    net::post(ws_.get_executor(), [self = shared_from_this(), reason] {
      self->ws_.async_close(websocket::close_reason(websocket::close_code::going_away, reason),
                            [self](beast::error_code) {});
    });
  }

 private:
  struct Message {
    bool binary;
    std::string data;
  };

  static bool is_frame_result(const Message& m) {
    return m.binary && m.data.size() >= 4 && message_tag(m.data) == Tag::FrameResult;
  }

  void enqueue(bool binary, std::string data) {
    Message m{binary, std::move(data)};
    // The front is being written; a frame result waiting behind it is superseded by a newer one.
    if (queue_.size() > 1 && is_frame_result(m) && is_frame_result(queue_.back())) {
      queue_.back() = std::move(m);
      return;
    }
    queue_.push_back(std::move(m));
    if (queue_.size() == 1) write_next();
  }

  void write_next() {
    ws_.binary(queue_.front().binary);
    ws_.async_write(net::buffer(queue_.front().data),
                    [self = shared_from_this()](beast::error_code ec, size_t) {
                      if (ec) return self->queue_.clear();
                      self->queue_.pop_front();
                      if (!self->queue_.empty()) self->write_next();
                    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  std::deque<Message> queue_;
};

// Whether a text message is of `type` (the JSON's keys are sorted: "type" is not the first; a
// string value cannot hold the unescaped quotes).
bool is_type(const std::string& message, const std::string& type) {
  return message.find(R"("type":")" + type + '"') != std::string::npos;
}

}  // namespace

struct EditorServer::Impl {
  ServerConfig config;
  std::map<std::string, Asset> assets;
  std::set<std::string> allowed_hosts;  // "host:port" values of the Host header
  net::io_context io{1};
  tcp::acceptor acceptor{io};
  net::signal_set signals{io, SIGINT, SIGTERM};
  Mailbox mailbox;
  std::unique_ptr<EditorSession> session;
  std::mutex connection_mutex;
  std::shared_ptr<Connection> connection;  // the editor window being served
  std::string progress;                    // the last progress message while one is running
  // The mesh's notice (and its look) whose basis is computed: binary or not, and the message.
  std::vector<std::pair<bool, std::string>> preparing;
  // The mesh's parts (101) do not go over the socket: they are gathered into one body that the
  // page fetches (GET /mesh/ID, as the text message {"type": "mesh", "id", "bytes"} says, or
  // /mesh/latest as it starts), in a fraction of the time a WebSocket takes to carry the 25 MB
  // of a 692k mesh into a browser.
  std::string mesh_parts;  // of the mesh being sent
  // The last whole one's id (unique to this run: a page that reconnects to another server run
  // does not take a mesh for one it has) and its parts, one after the other.
  const std::string mesh_run = std::to_string(std::random_device{}());
  int mesh_count = 0;
  std::string mesh_id;
  std::shared_ptr<const std::string> mesh;

  void send(bool binary, std::string data) {
    std::shared_ptr<Connection> c;
    {
      std::lock_guard lock(connection_mutex);
      if (binary && message_tag(data) == Tag::Mesh) {
        std::optional<std::string> notice = gather_mesh(data);
        if (!notice) return;
        std::tie(binary, data) = std::pair(false, std::move(*notice));
      }
      c = connection;
      const bool is_progress = !binary && is_type(data, "progress");
      if (!is_progress && !binary) progress.clear();
      if (is_progress) progress = data;
      keep_preparing(binary, data);
    }
    if (c) c->send(binary, std::move(data));
  }

  // Takes a mesh part; returns the page's notice once the mesh's last part came.
  std::optional<std::string> gather_mesh(const std::string& part) {
    if (starts_mesh(part)) mesh_parts.clear();
    mesh_parts += part;
    const MeshPartHeader h = mesh_part_header(part);
    if (h.kind != 1 || h.first + h.count != h.triangles) return std::nullopt;
    mesh = std::make_shared<const std::string>(std::exchange(mesh_parts, {}));
    mesh_id = mesh_run + "-" + std::to_string(++mesh_count);
    return R"({"bytes":)" + std::to_string(mesh->size()) + R"(,"id":")" + mesh_id +
           R"(","type":"mesh"})";
  }

  // The mesh's notice (and look) sent before its basis, for a window that connects while the
  // basis is computed; forgotten when the mesh is ready or was not opened (ready, empty, error).
  void keep_preparing(bool binary, const std::string& data) {
    if (!binary) {
      if (is_type(data, "mesh")) preparing = {{false, data}};
      if (is_type(data, "ready") || is_type(data, "empty") || is_type(data, "error")) {
        preparing.clear();
      }
      return;
    }
    const Tag tag = message_tag(data);
    if (!preparing.empty() && (tag == Tag::Appearance || tag == Tag::Texture)) {
      preparing.emplace_back(true, data);
    }
  }

  // Returns whether the connection got the mesh being prepared (its hello then skips it: the
  // rest of the build is sent to it as it happens).
  bool attach(const std::shared_ptr<Connection>& c) {
    std::shared_ptr<Connection> previous;
    bool has_mesh = false;
    {
      std::lock_guard lock(connection_mutex);
      previous = std::exchange(connection, c);
      for (const auto& [binary, m] : preparing) c->send(binary, m);
      has_mesh = !preparing.empty();
      if (!progress.empty()) c->send(false, progress);
    }
    if (previous) previous->close("another editor window connected");
    return has_mesh;
  }

  void detach(const std::shared_ptr<Connection>& c) {
    std::lock_guard lock(connection_mutex);
    if (connection == c) connection.reset();
  }

  http::response<http::string_body> reply(const http::request<http::string_body>& req,
                                          http::status status, std::string body,
                                          const std::string& type) {
    http::response<http::string_body> res{status, req.version()};
    res.set(http::field::server, "specdeform");
    res.set(http::field::content_type, type);
    res.set("X-Content-Type-Options", "nosniff");
    res.set(http::field::cache_control, "no-cache");
    res.keep_alive(req.keep_alive());
    if (req.method() == http::verb::head) {
      res.content_length(body.size());
    } else {
      res.body() = std::move(body);
      res.prepare_payload();
    }
    return res;
  }

  http::response<http::string_body> serve_file(const http::request<http::string_body>& req) {
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      return reply(req, http::status::method_not_allowed, "method not allowed\n", "text/plain");
    }
    std::string target(req.target());
    target = target.substr(0, target.find_first_of("?#"));
    if (target.starts_with("/mesh/")) {
      std::shared_ptr<const std::string> body;
      std::string id;
      {
        std::lock_guard lock(connection_mutex);
        if (target == "/mesh/" + mesh_id || (mesh && target == "/mesh/latest")) {
          std::tie(body, id) = std::pair(mesh, mesh_id);
        }
      }
      if (!body) return reply(req, http::status::not_found, "not the open mesh\n", "text/plain");
      auto res = reply(req, http::status::ok, *body, "application/octet-stream");
      res.set("X-Mesh-Id", id);
      return res;
    }
    const auto it = assets.find(target);
    if (it == assets.end()) return reply(req, http::status::not_found, "not found\n", "text/plain");
    return reply(req, http::status::ok, it->second.body, it->second.type);
  }

  bool host_allowed(const http::request<http::string_body>& req) const {
    return allowed_hosts.count(std::string(req[http::field::host])) > 0;
  }

  bool origin_allowed(const http::request<http::string_body>& req) const {
    const std::string origin(req[http::field::origin]);
    const std::string prefix = "http://";
    return origin.starts_with(prefix) && allowed_hosts.count(origin.substr(prefix.size())) > 0;
  }

  awaitable<void> serve_websocket(beast::tcp_stream stream, http::request<http::string_body> req) {
    stream.expires_never();
    websocket::stream<beast::tcp_stream> ws(std::move(stream));
    ws.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws.read_message_max(config.max_message_bytes);
    co_await ws.async_accept(req, use_awaitable);
    auto c = std::make_shared<Connection>(std::move(ws));
    // The connection's one greeting (the page sends none): the edit, once the worker is free.
    const std::string hello =
        attach(c) ? R"({"type":"hello","has_mesh":true})" : R"({"type":"hello"})";
    mailbox.push([this, hello] { session->handle(false, hello); }, false);
    try {
      for (;;) {
        beast::flat_buffer buffer;
        co_await c->ws().async_read(buffer, use_awaitable);
        const bool binary = c->ws().got_binary();
        auto data = std::make_shared<std::string>(beast::buffers_to_string(buffer.data()));
        if (!binary && *data == R"({"type":"cancel"})") {
          session->cancel();  // at once: the worker is busy with what it cancels
          continue;
        }
        const bool frame = binary && data->size() >= 4 && message_tag(*data) == Tag::Frame;
        mailbox.push([this, binary, data] { session->handle(binary, *data); }, frame);
      }
    } catch (const boost::system::system_error&) {
    }
    detach(c);
  }

  awaitable<void> serve_http(tcp::socket socket) {
    beast::tcp_stream stream(std::move(socket));
    beast::flat_buffer buffer;
    try {
      for (;;) {
        stream.expires_after(std::chrono::seconds(60));
        http::request_parser<http::string_body> parser;
        parser.body_limit(1 << 16);
        co_await http::async_read(stream, buffer, parser, use_awaitable);
        http::request<http::string_body> req = parser.release();
        if (!host_allowed(req)) {
          co_await http::async_write(
              stream, reply(req, http::status::forbidden, "unknown host\n", "text/plain"),
              use_awaitable);
          break;
        }
        if (websocket::is_upgrade(req)) {
          if (!origin_allowed(req)) {
            co_await http::async_write(
                stream, reply(req, http::status::forbidden, "origin not allowed\n", "text/plain"),
                use_awaitable);
            break;
          }
          co_await serve_websocket(std::move(stream), std::move(req));
          co_return;
        }
        const bool keep_alive = req.keep_alive();
        co_await http::async_write(stream, serve_file(req), use_awaitable);
        if (!keep_alive) break;
      }
      stream.socket().shutdown(tcp::socket::shutdown_send);
    } catch (const boost::system::system_error&) {
    }
  }

  awaitable<void> listen() {
    for (;;) {
      tcp::socket socket = co_await acceptor.async_accept(use_awaitable);
      // Small frame messages go out at once, not held back for an acknowledgement (Nagle).
      boost::system::error_code ignored;
      socket.set_option(tcp::no_delay(true), ignored);
      net::co_spawn(io, serve_http(std::move(socket)), net::detached);
    }
  }
};

EditorServer::EditorServer(ServerConfig config, EditorConfig editor)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.config = std::move(config);
  s.assets = read_assets(s.config.assets);
  s.session = std::make_unique<EditorSession>(
      std::move(editor),
      [this](bool binary, std::string data) { impl_->send(binary, std::move(data)); },
      [this](std::function<void()> job) { impl_->mailbox.push(std::move(job), false); });
  boost::system::error_code ec;
  const net::ip::address address = net::ip::make_address(s.config.host, ec);
  if (ec) throw InputError("--host " + s.config.host + ": not an IP address");
  const tcp::endpoint endpoint(address, s.config.port);
  s.acceptor.open(endpoint.protocol(), ec);
  if (!ec) s.acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor.bind(endpoint, ec);
  if (!ec) s.acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) {
    throw InputError("cannot listen on " + s.config.host + ":" + std::to_string(s.config.port) +
                     ": " + ec.message());
  }
  const std::string p = std::to_string(port());
  const std::string host = address.is_v6() ? "[" + s.config.host + "]" : s.config.host;
  s.allowed_hosts = {host + ":" + p};
  if (address.is_loopback() || address.is_unspecified()) {
    s.allowed_hosts.insert({"127.0.0.1:" + p, "localhost:" + p, "[::1]:" + p});
  }
}

EditorServer::~EditorServer() = default;

EditorSession& EditorServer::session() {
  return *impl_->session;
}

void EditorServer::open_when_running(LoadedMesh mesh, std::string name) {
  auto job = [this, mesh = std::make_shared<LoadedMesh>(std::move(mesh)), name] {
    if (auto error = impl_->session->start(std::move(*mesh), name)) {
      std::cerr << "specdeform: " << *error << "\n";
    }
  };
  impl_->mailbox.push(std::move(job), false);
}

uint16_t EditorServer::port() const {
  return impl_->acceptor.local_endpoint().port();
}

std::string EditorServer::url() const {
  const std::string& h = impl_->config.host;
  const bool any = h == "0.0.0.0" || h == "::";
  const bool v6 = h.find(':') != std::string::npos;
  return "http://" +
         (any  ? std::string("127.0.0.1")
          : v6 ? "[" + h + "]"
               : h) +
         ":" + std::to_string(port()) + "/";
}

void EditorServer::run() {
  Impl& s = *impl_;
  std::thread worker([&s] {
    while (std::optional<Mailbox::Job> job = s.mailbox.pop()) (*job)();
  });
  s.signals.async_wait([this](beast::error_code, int) { stop(); });
  net::co_spawn(s.io, s.listen(), net::detached);
  s.io.run();
  s.session->cancel();
  s.mailbox.close();
  worker.join();
}

void EditorServer::stop() {
  net::post(impl_->io, [this] { impl_->io.stop(); });
}

}  // namespace specdeform::server
