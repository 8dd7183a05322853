#include "protocol.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "specdeform/exceptions.h"

namespace specdeform::server {
namespace {

GroupSelection groups(Selection s) {
  const size_t g = s.handles.size();
  return {std::move(s), std::vector<Eigen::Affine3d>(g, Eigen::Affine3d::Identity()),
          std::vector<bool>(g, false), std::vector<bool>(g, false)};
}

TEST(Protocol, SelectionRoundTrips) {
  GroupSelection s = groups({{{3, 1}, {}, {7}}, {0, 5}});
  s.transforms[1] =
      Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX());
  s.pinned[2] = true;
  s.fit[2] = true;
  s.echo = true;
  const GroupSelection back = decode_selection(encode_selection(s, Tag::Selection), 8);
  EXPECT_EQ(back.selection.handles, s.selection.handles);
  EXPECT_EQ(back.selection.fixed, s.selection.fixed);
  EXPECT_EQ(back.pinned, s.pinned);
  EXPECT_EQ(back.fit, s.fit);
  EXPECT_TRUE(back.echo);
  EXPECT_TRUE(back.transforms[1].matrix().isApprox(s.transforms[1].matrix(), 0));
}

TEST(Protocol, SelectionRejectsBadMessages) {
  const std::string good = encode_selection(groups({{{3, 1}}, {0}}), Tag::Selection);
  EXPECT_THROW(decode_selection(good, 3), InputError);  // vertex 3 of a 3-vertex mesh
  EXPECT_THROW(decode_selection(good.substr(0, good.size() - 4), 8), InputError);
  EXPECT_THROW(decode_selection(good + std::string(4, '\0'), 8), InputError);
  EXPECT_THROW(decode_selection(good.substr(0, 6), 8), InputError);
  Selection many;
  many.handles.resize(kMaxGroups + 1);
  EXPECT_THROW(decode_selection(encode_selection(groups(many), Tag::Selection), 8), InputError);
  // A group size that would overflow 32 bits when multiplied by 4.
  std::string huge = encode_selection(groups({{{}}, {}}), Tag::Selection);
  const uint32_t big = 0x40000001;
  huge.replace(16, 4, reinterpret_cast<const char*>(&big), 4);
  EXPECT_THROW(decode_selection(huge, 8), InputError);
  std::string flags = good;  // unknown group flags
  const uint32_t four = 4;
  flags.replace(20, 4, reinterpret_cast<const char*>(&four), 4);
  EXPECT_THROW(decode_selection(flags, 8), InputError);
  GroupSelection singular = groups({{{1}}, {}});
  singular.transforms[0].linear().setZero();
  EXPECT_THROW(decode_selection(encode_selection(singular, Tag::Selection), 8), InputError);
}

TEST(Protocol, FrameRoundTripsAndValidates) {
  Eigen::Affine3d t =
      Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY());
  const FrameRequest f{42, {t, Eigen::Affine3d::Identity()}};
  const FrameRequest back = decode_frame(encode_frame(f), 2);
  EXPECT_EQ(back.seq, 42u);
  EXPECT_FALSE(back.preview);
  EXPECT_TRUE(decode_frame(encode_frame({1, {t, t}, true}), 2).preview);
  ASSERT_EQ(back.transforms.size(), 2u);
  EXPECT_TRUE(back.transforms[0].matrix().isApprox(t.matrix(), 0));
  EXPECT_THROW(decode_frame(encode_frame(f), 1), InputError);  // group count mismatch

  const auto with = [&](int entry, double value) {
    FrameRequest g = f;
    g.transforms[0].matrix()(entry / 4, entry % 4) = value;
    return encode_frame(g);
  };
  EXPECT_THROW(decode_frame(with(5, std::numeric_limits<double>::quiet_NaN()), 2), InputError);
  EXPECT_THROW(decode_frame(with(3, std::numeric_limits<double>::infinity()), 2), InputError);
  EXPECT_THROW(decode_frame(with(12, 0.5), 2), InputError);  // not affine
  FrameRequest singular = f;
  singular.transforms[0].linear().setZero();
  EXPECT_THROW(decode_frame(encode_frame(singular), 2), InputError);
  const std::string good = encode_frame(f);
  EXPECT_THROW(decode_frame(good.substr(0, good.size() - 8), 2), InputError);
}

TEST(Protocol, FileRoundTripsAndValidates) {
  const NamedFile f{"bunny.obj", std::string("v 0 0 0\n\0binary", 15)};
  const NamedFile back = decode_file(encode_file(f, Tag::MeshFile));
  EXPECT_EQ(back.name, f.name);
  EXPECT_EQ(back.data, f.data);
  EXPECT_THROW(decode_file(encode_file({"", "x"}, Tag::MeshFile)), InputError);
  EXPECT_THROW(decode_file(encode_file({"a\nb.obj", "x"}, Tag::MeshFile)), InputError);
  EXPECT_THROW(decode_file(encode_file({std::string(kMaxNameLength + 1, 'a'), ""}, Tag::MeshFile)),
               InputError);
  EXPECT_THROW(decode_file(encode_file(f, Tag::MeshFile).substr(0, 10)), InputError);
}

TEST(Protocol, MeshAndFrameResultLayouts) {
  TriangleMesh m{Vertices(3, 3), Faces(1, 3)};
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  m.F << 0, 1, 2;
  // Parts of two: positions of vertices 0-1 and 2, then the triangle.
  const std::vector<std::string> parts = encode_mesh_parts(m, 2);
  ASSERT_EQ(parts.size(), 3u);
  const std::vector<std::vector<uint32_t>> headers{
      {101, 3, 1, 0, 0, 2}, {101, 3, 1, 0, 2, 1}, {101, 3, 1, 1, 0, 1}};
  for (size_t p = 0; p < parts.size(); ++p) {
    std::vector<uint32_t> header(6);
    std::memcpy(header.data(), parts[p].data(), 24);
    EXPECT_EQ(header, headers[p]);
    EXPECT_EQ(parts[p].size(), 24u + 12u * header[5]);
    EXPECT_EQ(starts_mesh(parts[p]), p == 0);
  }
  float y = 0;
  std::memcpy(&y, parts[0].data() + 24 + 16, 4);  // vertex 1's y
  EXPECT_EQ(y, 0.0f);
  std::memcpy(&y, parts[1].data() + 24 + 4, 4);  // vertex 2's y
  EXPECT_EQ(y, 1.0f);
  uint32_t corner = 0;
  std::memcpy(&corner, parts[2].data() + 24 + 8, 4);
  EXPECT_EQ(corner, 2u);
  Vertices moved = m.V;
  moved(1, 0) += 0.5;
  moved(2, 2) -= 0.25;
  const std::string frame =
      encode_frame_result(9, {true, false}, {0.001, 0, 0, 0.002, 1e-6, 1e-7, 7, false}, moved, m.V);
  EXPECT_EQ(frame.size(), 52u + 20u);  // 9 displacements of 2 bytes, padded to 4
  float total_ms = 0;
  std::memcpy(&total_ms, frame.data() + 28, 4);
  EXPECT_FLOAT_EQ(total_ms, 2.0f);
  uint32_t iterations = 0, converged = 1;
  std::memcpy(&iterations, frame.data() + 40, 4);
  std::memcpy(&converged, frame.data() + 44, 4);
  EXPECT_EQ(iterations, 7u);
  EXPECT_EQ(converged, 0u);
  // Positions within half a step (the largest displacement / 32767) of the sent ones.
  EXPECT_LT((decode_frame_positions(frame, m.V) - moved).cwiseAbs().maxCoeff(),
            0.5 / 32767 * 0.5 + 1e-7);
  EXPECT_THROW(decode_frame_positions(frame.substr(0, 60), m.V), InputError);
  // A preview frame carries the preview's vertices only, in its order.
  const PreviewMesh preview{{2, 1}, Faces(0, 3)};
  const Vertices at_preview = moved(std::vector<int>{2, 1}, Eigen::all);
  const std::string coarse = encode_frame_result(3, {false, true}, {}, at_preview, m.V, &preview);
  EXPECT_EQ(coarse.size(), 52u + 12u);
  EXPECT_LT((decode_frame_positions(coarse, m.V, &preview) - at_preview).cwiseAbs().maxCoeff(),
            1e-4);
  EXPECT_THROW(encode_frame_result(3, {false, true}, {}, moved, m.V, &preview), InputError);
  uint32_t view = 0;
  std::memcpy(&view, coarse.data() + 12, 4);
  EXPECT_EQ(view, 2u);
  FrameStats folded;
  folded.fold_zone = 12;
  std::memcpy(&view, encode_frame_result(4, {}, folded, moved, m.V).data() + 12, 4);
  EXPECT_EQ(view, 4u);  // bit 2: details added as displacements where the base folded
  const Vertices back = decode_frame_positions(coarse, m.V, &preview);
  EXPECT_NEAR(back(0, 2), moved(2, 2), 0.5 / 32767);
  EXPECT_NEAR(back(1, 0), moved(1, 0), 0.5 / 32767);
  EXPECT_EQ(encode_preview(preview).size(), 12u + 8u);
  // A solve at the rest pose differs from it by rounding only: sent as no motion (scale 1, bit
  // 3: at rest, no displacements follow), not rounding scaled up to the int16 range.
  Vertices noise = m.V;
  noise(1, 0) += 3e-15;
  noise(2, 1) -= 1e-15;
  const std::string still = encode_frame_result(5, {}, {}, noise, m.V);
  EXPECT_EQ(still.size(), 52u);
  float scale = 0;
  std::memcpy(&scale, still.data() + 48, 4);
  EXPECT_EQ(scale, 1.0f);
  std::memcpy(&view, still.data() + 12, 4);
  EXPECT_EQ(view, 8u);
  EXPECT_EQ(decode_frame_positions(still, m.V), m.V);
  EXPECT_THROW(message_tag("ab"), InputError);
}

}  // namespace
}  // namespace specdeform::server
