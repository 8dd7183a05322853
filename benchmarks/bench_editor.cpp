// End-to-end throughput of the editor's server, as the browser sees it minus drawing: a
// WebSocket client (Boost.Beast) sends a selection, then drags the handle with a stream of
// frame messages, and times each frame from sending it to receiving its deformed mesh.
//
//   bench_editor [MESH] [--seconds S] [--hz H] [--hand V] [--modes M] [--eigensolver NAME]
//
// MESH defaults to ../shared/meshes/models/armadillo.obj (the built-in bumpy bar without it).
// Scene: benchmark_scene() (scene.h), or with --hand V the vertices within 5% of the diagonal
// of vertex V as the handle and the lowest 10% along y fixed. No basis cache; the eigensolver
// is the editor's default for the mesh's size unless named. Printed as one JSON object: the
// time to open the file (read it, compute the basis, build the deformer), the selection's
// server time, the first frame's latency, the first drag's result from opening, the time
// until the transfer's background factorisation is ready (its "detail" state; the drags below
// wait for it), a paint stroke's time (the selection again with the fixed region grown by the
// vertices of one more handle-sized patch, until its state comes back; then until its transfer
// is ready), and two runs:
//  - "mouse": frames sent at H per second (default 60, a mouse) for S seconds (default 4): the
//    results per second that come back and the latency of each (median, 90th percentile);
//  - "closed_loop": the next frame sent as soon as the previous result arrives: the most
//    updates per second the server and the connection can carry.
#include <utility>  // before Boost.Asio, whose awaitable.hpp uses std::exchange

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <thread>

#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <nlohmann/json.hpp>

#include "editor_server.h"
#include "huge_pages_start.h"
#include "protocol.h"
#include "specdeform/deform/scene.h"

namespace sd = specdeform;
namespace net = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;
using Ws = websocket::stream<beast::tcp_stream>;

namespace {

double ms(Clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * v.size()))];
}

struct Drag {
  Eigen::Vector3d move;  // where the handle ends up
  int frames;
  std::string frame(int k) const {
    const double s = static_cast<double>(k) / frames;
    return sd::server::encode_frame(
        {static_cast<uint32_t>(k), {Eigen::Affine3d(Eigen::Translation3d(s * move))}});
  }
};

// Reads until a frame result; returns its seq and the server's solve time (ms).
net::awaitable<std::pair<uint32_t, float>> next_result(Ws& ws) {
  for (;;) {
    beast::flat_buffer buffer;
    co_await ws.async_read(buffer, net::use_awaitable);
    const std::string m = beast::buffers_to_string(buffer.data());
    if (!ws.got_binary()) {
      if (m.find("\"error\"") != std::string::npos) throw std::runtime_error(m);
      continue;
    }
    if (sd::server::message_tag(m) != sd::server::Tag::FrameResult) continue;
    uint32_t seq;
    float total;
    std::memcpy(&seq, m.data() + 4, 4);
    std::memcpy(&total, m.data() + 28, 4);
    co_return std::pair{seq, total};
  }
}

net::awaitable<void> run_client(uint16_t port, sd::Selection selection, std::vector<int> stroke,
                                Drag drag, double hz, nlohmann::ordered_json& out) {
  auto ex = co_await net::this_coro::executor;
  Ws ws(ex);
  co_await beast::get_lowest_layer(ws).async_connect(
      tcp::endpoint(net::ip::make_address("127.0.0.1"), port), net::use_awaitable);
  beast::get_lowest_layer(ws).socket().set_option(tcp::no_delay(true));
  const std::string host = "127.0.0.1:" + std::to_string(port);
  ws.set_option(websocket::stream_base::decorator([host](websocket::request_type& req) {
    req.set(beast::http::field::origin, "http://" + host);
  }));
  co_await ws.async_handshake(host, "/ws", net::use_awaitable);
  ws.binary(true);
  ws.read_message_max(std::size_t{1} << 31);  // a large mesh's rest shape is one message
  sd::server::GroupSelection groups;
  groups.selection = selection;
  groups.transforms.assign(selection.handles.size(), Eigen::Affine3d::Identity());
  groups.pinned.assign(selection.handles.size(), false);
  const std::string message = sd::server::encode_selection(groups, sd::server::Tag::Selection);
  // Reads up to the count-th "state" answering `request` ("detail": the transfer's background
  // factorisation is ready); returns it.
  const auto states = [&](int count, std::string_view request) -> net::awaitable<nlohmann::json> {
    for (;;) {
      beast::flat_buffer buffer;
      co_await ws.async_read(buffer, net::use_awaitable);
      if (ws.got_binary()) continue;
      const nlohmann::json m = nlohmann::json::parse(beast::buffers_to_string(buffer.data()));
      if (m["type"] == "error") throw std::runtime_error(m.dump());
      if (m["type"] == "state" && (request.empty() || m["request"] == request) && --count == 0) {
        co_return m;
      }
    }
  };
  const Clock::time_point selecting = Clock::now();
  co_await ws.async_write(net::buffer(message), net::use_awaitable);
  co_await states(1, "hello");
  const bool pending = (co_await states(1, "selection"))["detail_pending"];
  out["selection_seconds"] = ms(Clock::now() - selecting) / 1e3;
  const Clock::time_point first = Clock::now();
  co_await ws.async_write(net::buffer(drag.frame(1)), net::use_awaitable);
  co_await next_result(ws);
  out["first_frame_ms"] = ms(Clock::now() - first);
  out["first_drag_seconds"] =
      out["open_seconds"].get<double>() + ms(Clock::now() - selecting) / 1e3;
  if (pending) co_await states(1, "detail");  // the drags below with the transfer's details
  out["transfer_ready_seconds"] = ms(Clock::now() - selecting) / 1e3;

  // A mouse: frames at a fixed rate, results read as they come.
  std::map<uint32_t, Clock::time_point> sent;
  std::vector<double> latency, solve;
  bool sending = true;
  const Clock::time_point start = Clock::now();
  net::co_spawn(
      ex,
      [&]() -> net::awaitable<void> {
        net::steady_timer timer(ex);
        for (int k = 1; k <= drag.frames; ++k) {
          timer.expires_at(start + std::chrono::microseconds(static_cast<long>(1e6 * k / hz)));
          co_await timer.async_wait(net::use_awaitable);
          sent[k] = Clock::now();
          co_await ws.async_write(net::buffer(drag.frame(k)), net::use_awaitable);
        }
        sending = false;
      },
      net::detached);
  int results = 0;
  uint32_t last = 0;
  while (sending || last < static_cast<uint32_t>(drag.frames)) {
    const auto [seq, total] = co_await next_result(ws);
    latency.push_back(ms(Clock::now() - sent.at(seq)));
    solve.push_back(total);
    last = seq;
    ++results;
  }
  const double seconds = ms(Clock::now() - start) / 1e3;
  out["mouse"] = {{"frames_sent", drag.frames},
                  {"hz", hz},
                  {"results", results},
                  {"results_per_second", results / seconds},
                  {"latency_ms_median", percentile(latency, 0.5)},
                  {"latency_ms_p90", percentile(latency, 0.9)},
                  {"server_solve_ms_median", percentile(solve, 0.5)}};

  // Closed loop: the next frame as soon as the previous one is back.
  std::vector<double> round_trip;
  const Clock::time_point loop_start = Clock::now();
  for (int k = 1; k <= drag.frames; ++k) {
    const Clock::time_point t = Clock::now();
    co_await ws.async_write(net::buffer(drag.frame(drag.frames - k)), net::use_awaitable);
    co_await next_result(ws);
    round_trip.push_back(ms(Clock::now() - t));
  }
  out["closed_loop"] = {{"frames", drag.frames},
                        {"updates_per_second", drag.frames / (ms(Clock::now() - loop_start) / 1e3)},
                        {"round_trip_ms_median", percentile(round_trip, 0.5)}};

  // A stroke: the fixed region grows by `stroke` vertices.
  groups.selection.fixed.insert(groups.selection.fixed.end(), stroke.begin(), stroke.end());
  const Clock::time_point stroking = Clock::now();
  co_await ws.async_write(
      net::buffer(sd::server::encode_selection(groups, sd::server::Tag::Selection)),
      net::use_awaitable);
  const bool stroke_pending = (co_await states(1, "selection"))["detail_pending"];
  out["stroke_seconds"] = ms(Clock::now() - stroking) / 1e3;
  out["stroke_vertices"] = stroke.size();
  if (stroke_pending) co_await states(1, "detail");
  out["stroke_transfer_seconds"] = ms(Clock::now() - stroking) / 1e3;
  co_await ws.async_close(websocket::close_code::normal, net::use_awaitable);
}

}  // namespace

int main(int argc, char** argv) {
  specdeform::apps::restart_with_huge_pages(argv);  // as the editor's server runs
  std::filesystem::path mesh_path =
      std::filesystem::path(SPECDEFORM_SHARED_DIR) / "meshes/models/armadillo.obj";
  double seconds = 4, hz = 60;
  int hand = -1, modes = 100;
  std::optional<sd::EigenSolver> eigensolver;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string("0"); };
    if (a == "--seconds")
      seconds = std::stod(value());
    else if (a == "--hz")
      hz = std::stod(value());
    else if (a == "--hand")
      hand = std::stoi(value());
    else if (a == "--modes")
      modes = std::stoi(value());
    else if (a == "--eigensolver")
      eigensolver = sd::eigen_solver_from_name(value());
    else
      mesh_path = a;
  }
  try {
    const Clock::time_point opening = Clock::now();
    const bool found = std::filesystem::exists(mesh_path);
    sd::LoadedMesh mesh = found ? sd::read_mesh(mesh_path) : sd::server::demo_mesh();
    const std::string name = found ? mesh_path.filename().string() : sd::server::kDemoName;
    sd::Scene scene = sd::benchmark_scene(mesh.mesh);
    if (hand >= 0) scene.selection = sd::radius_selection(mesh.mesh, hand, 0.05, 0.10, 1);
    nlohmann::ordered_json out;
    out["mesh"] = name;
    out["vertices"] = mesh.mesh.num_vertices();
    out["modes"] = modes;
    out["handle_vertices"] = scene.selection.handles[0].size();
    out["fixed_vertices"] = scene.selection.fixed.size();
    // The stroke: the free vertices within 3% of the diagonal of the free vertex farthest from
    // the handle.
    std::vector<char> selected(mesh.mesh.num_vertices(), 0);
    for (const auto& group : scene.selection.handles)
      for (const int v : group) selected[v] = 1;
    for (const int v : scene.selection.fixed) selected[v] = 1;
    Eigen::VectorXd distance =
        (mesh.mesh.V.rowwise() - mesh.mesh.V.row(scene.selection.handles[0][0])).rowwise().norm();
    for (int v = 0; v < mesh.mesh.num_vertices(); ++v)
      if (selected[v]) distance[v] = -1.0;
    Eigen::Index far = 0;
    distance.maxCoeff(&far);
    std::vector<int> stroke =
        sd::radius_selection(mesh.mesh, static_cast<int>(far), 0.03, 0.0, 1).handles[0];
    std::erase_if(stroke, [&](int v) { return selected[v] != 0; });
    sd::server::EditorServer server({.port = 0, .assets = SPECDEFORM_WEB_DIST},
                                    {.modes = modes, .eigensolver = eigensolver});
    server.session().open(std::move(mesh), name);
    out["open_seconds"] = ms(Clock::now() - opening) / 1e3;
    std::thread serving([&] { server.run(); });
    const Drag drag{scene.transforms[0].translation(), static_cast<int>(seconds * hz)};
    net::io_context io;
    std::exception_ptr failure;
    net::co_spawn(io, run_client(server.port(), scene.selection, stroke, drag, hz, out),
                  [&](std::exception_ptr e) { failure = e; });
    io.run();
    server.stop();
    serving.join();
    if (failure) std::rethrow_exception(failure);
    std::cout << out.dump(1) << "\n";
  } catch (const std::exception& e) {
    std::cerr << "bench_editor: " << e.what() << "\n";
    return 1;
  }
}
