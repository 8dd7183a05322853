#include "editor_server.h"

#include <utility>  // before Boost.Asio, whose awaitable.hpp uses std::exchange

#include <cstring>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <nlohmann/json.hpp>

#include "protocol.h"
#include "specdeform/mesh/generate.h"

namespace specdeform::server {
namespace {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;

// A server on a free port of 127.0.0.1, serving a small sphere and two asset files, on a thread.
class EditorServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    assets_ = std::filesystem::temp_directory_path() /
              ("specdeform-assets-" + std::to_string(::getpid()));
    std::filesystem::create_directories(assets_ / "assets");
    std::ofstream(assets_ / "index.html") << "<!doctype html><title>editor</title>";
    std::ofstream(assets_ / "assets" / "app.js") << "console.log(1)";
    std::filesystem::create_symlink("/etc/hostname", assets_ / "linked.txt");
    server_ = std::make_unique<EditorServer>(
        ServerConfig{.port = 0, .assets = assets_, .max_message_bytes = 1 << 20},
        EditorConfig{.modes = 20});
    LoadedMesh mesh;
    mesh.mesh = make_icosphere(2);
    mesh.info = identity_read_info(mesh.mesh);
    server_->session().open(std::move(mesh), "sphere.obj");
    thread_ = std::thread([this] { server_->run(); });
  }

  void TearDown() override {
    server_->stop();
    thread_.join();
    std::filesystem::remove_all(assets_);
  }

  http::response<http::string_body> get(const std::string& target, const std::string& host = "",
                                        http::verb verb = http::verb::get) {
    net::io_context io;
    beast::tcp_stream stream(io);
    stream.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), server_->port()));
    http::request<http::string_body> req{verb, target, 11};
    req.set(http::field::host,
            host.empty() ? "127.0.0.1:" + std::to_string(server_->port()) : host);
    http::write(stream, req);
    beast::flat_buffer buffer;
    http::response<http::string_body> res;
    http::read(stream, buffer, res);
    return res;
  }

  // Opens a WebSocket with the given Origin; throws if the handshake is refused.
  std::unique_ptr<websocket::stream<tcp::socket>> connect(const std::string& origin) {
    auto ws = std::make_unique<websocket::stream<tcp::socket>>(io_);
    ws->next_layer().connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), server_->port()));
    ws->set_option(websocket::stream_base::decorator(
        [origin](websocket::request_type& req) { req.set(http::field::origin, origin); }));
    ws->handshake("127.0.0.1:" + std::to_string(server_->port()), "/ws");
    return ws;
  }

  std::string own_origin() const { return "http://127.0.0.1:" + std::to_string(server_->port()); }

  // The next text message.
  static nlohmann::json next_text(websocket::stream<tcp::socket>& ws) {
    for (;;) {
      beast::flat_buffer buffer;
      ws.read(buffer);
      if (!ws.got_binary()) return nlohmann::json::parse(beast::buffers_to_string(buffer.data()));
    }
  }

  // Reads messages until a text message of `type` (or, when `type` is "error", of "ready" after
  // it) arrives.
  static nlohmann::json read_until(websocket::stream<tcp::socket>& ws, const std::string& type) {
    for (;;) {
      nlohmann::json j = next_text(ws);
      if (j["type"] == type || (type == "error" && j["type"] == "ready")) return j;
    }
  }

  std::filesystem::path assets_;
  std::unique_ptr<EditorServer> server_;
  std::thread thread_;
  net::io_context io_;
};

TEST_F(EditorServerTest, ServesOnlyTheBuiltAssets) {
  EXPECT_EQ(get("/").result(), http::status::ok);
  EXPECT_EQ(get("/").body(), "<!doctype html><title>editor</title>");
  const auto js = get("/assets/app.js?v=1");
  EXPECT_EQ(js.result(), http::status::ok);
  EXPECT_EQ(js[http::field::content_type], "text/javascript");
  EXPECT_EQ(get("/../../etc/passwd").result(), http::status::not_found);
  EXPECT_EQ(get("/assets/../index.html").result(), http::status::not_found);
  EXPECT_EQ(get("/linked.txt").result(), http::status::not_found);
  EXPECT_EQ(get("/", "evil.example:80").result(), http::status::forbidden);
  EXPECT_EQ(get("/", "", http::verb::post).result(), http::status::method_not_allowed);
  EXPECT_EQ(get("/", "localhost:" + std::to_string(server_->port())).result(), http::status::ok);
}

// The mesh's parts come over HTTP, as the socket's notice says: positions first, then
// triangles; a replaced mesh is not served.
TEST_F(EditorServerTest, ServesTheOpenMeshAsItsNoticeSays) {
  auto ws = connect(own_origin());
  const nlohmann::json notice = read_until(*ws, "mesh");
  const std::string id = notice["id"];
  const auto res = get("/mesh/" + id);
  ASSERT_EQ(res.result(), http::status::ok);
  EXPECT_EQ(res[http::field::content_type], "application/octet-stream");
  EXPECT_EQ(res["X-Mesh-Id"], id);
  const auto latest = get("/mesh/latest");  // what a page fetches as it starts
  EXPECT_EQ(latest["X-Mesh-Id"], id);
  EXPECT_EQ(latest.body(), res.body());
  const std::string& body = res.body();
  ASSERT_EQ(body.size(), notice["bytes"].get<size_t>());
  ASSERT_TRUE(starts_mesh(body));
  size_t at = 0, vertices = 0, triangles = 0;
  for (; at + 24 <= body.size(); at += 24 + 12 * mesh_part_header(body.substr(at)).count) {
    EXPECT_EQ(message_tag(body.substr(at)), Tag::Mesh);
    const MeshPartHeader h = mesh_part_header(body.substr(at));
    (h.kind == 0 ? vertices : triangles) += h.count;
  }
  EXPECT_EQ(at, body.size());
  EXPECT_EQ(vertices, 162u);
  EXPECT_EQ(triangles, 320u);
  EXPECT_EQ(get("/mesh/" + id + "0").result(), http::status::not_found);
  EXPECT_EQ(get("/mesh/" + id, "evil.example:80").result(), http::status::forbidden);
}

TEST_F(EditorServerTest, RefusesWebSocketsFromOtherOrigins) {
  EXPECT_THROW(connect("http://evil.example"), boost::system::system_error);
  EXPECT_THROW(connect(""), boost::system::system_error);
  EXPECT_NO_THROW(connect(own_origin()));
}

TEST_F(EditorServerTest, AnswersMessagesAndSurvivesBadOnes) {
  auto ws = connect(own_origin());
  EXPECT_EQ(read_until(*ws, "ready")["vertices"], 162);
  ws->binary(true);
  ws->write(net::buffer(std::string("\x02\0\0", 3)));
  EXPECT_NE(read_until(*ws, "error")["message"].get<std::string>().find("truncated"),
            std::string::npos);
  ws->write(net::buffer(encode_selection(
      {{{{0, 1}}, {100}}, {Eigen::Affine3d::Identity()}, {false}, {false}}, Tag::Selection)));
  EXPECT_EQ(read_until(*ws, "state")["groups"][0]["vertices"], 2);
}

// The client announces a 2 MB message in a raw frame header (the server's limit is 1 MB) and reads
// the raw stream: the server answers with a close frame of code 1009 ("too big") at once, without
// waiting for the payload. (A client stream that writes the whole message may fail half-way when
// the server hangs up, and then cannot read the close frame.)
TEST_F(EditorServerTest, ClosesAConnectionThatSendsTooMuch) {
  auto ws = connect(own_origin());
  read_until(*ws, "ready");
  const std::uint64_t length = 2 << 20;
  std::string header = {'\x82', '\xff'};  // FIN + binary; masked, 64-bit length
  for (int shift = 56; shift >= 0; shift -= 8) header += char((length >> shift) & 0xff);
  header += std::string(4, '\0');  // the mask key
  net::write(ws->next_layer(), net::buffer(header));
  const std::string close_too_big = {'\x88', '\x02', '\x03', '\xf1'};  // unmasked, code 1009
  std::string received;
  boost::system::error_code ec;
  while (!ec && !received.ends_with(close_too_big)) {
    char chunk[4096];
    received.append(chunk, ws->next_layer().read_some(net::buffer(chunk), ec));
  }
  EXPECT_TRUE(received.ends_with(close_too_big)) << ec.message();
}

TEST_F(EditorServerTest, ANewWindowTakesOver) {
  auto first = connect(own_origin());
  read_until(*first, "ready");
  auto second = connect(own_origin());
  read_until(*second, "ready");
  beast::flat_buffer buffer;
  boost::system::error_code ec;
  while (!ec) first->read(buffer, ec);
  EXPECT_EQ(ec, websocket::error::closed);
}

// "cancel" is acted on while the worker computes a basis (it is not queued behind it): the
// computation's request is answered with a cancelled error, then the settings in force.
TEST_F(EditorServerTest, CancelStopsABasisComputationAtOnce) {
  auto ws = connect(own_origin());
  read_until(*ws, "ready");
  ws->binary(true);  // a mesh whose basis takes a while: 10242 vertices
  ws->write(net::buffer(
      encode_file({"big.obj", encode_mesh(make_icosphere(5), MeshFormat::Obj)}, Tag::MeshFile)));
  EXPECT_EQ(read_until(*ws, "ready")["vertices"], 10242);
  ws->text(true);
  ws->write(net::buffer(std::string(R"({"type":"settings","modes":150})")));
  EXPECT_TRUE(read_until(*ws, "progress")["cancellable"]);
  ws->write(net::buffer(std::string(R"({"type":"cancel"})")));
  // Queued behind the computation instead, the cancel would come too late: "ready" with m = 150.
  nlohmann::json error;
  for (nlohmann::json m = read_until(*ws, "error"); m["type"] != "ready"; m = next_text(*ws)) {
    if (m["type"] == "error") error = m;
  }
  EXPECT_EQ(error.value("cancelled", false), true) << error.dump();
  EXPECT_EQ(error.value("request", ""), "settings");
}

TEST(EditorServer, ReportsMissingAssetsAndBusyPorts) {
  EXPECT_THROW(EditorServer(ServerConfig{.assets = "/nonexistent"}, EditorConfig{}), InputError);
}

}  // namespace
}  // namespace specdeform::server
