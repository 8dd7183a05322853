// Data URIs with base64 payloads (mesh/formats/gltf/data_uri.h) and glTF's percent-encoded uris.
#include "mesh/formats/gltf/data_uri.h"

#include <gtest/gtest.h>

#include <random>

#include "mesh/formats/gltf/gltf_document.h"

namespace specdeform::detail {
namespace {

TEST(DataUri, RoundTripsEveryLength) {
  std::mt19937 rng(5);
  for (size_t n = 0; n < 40; ++n) {
    std::string bytes(n, '\0');
    for (char& c : bytes) c = char(rng());
    const std::string uri = encode_data_uri("application/octet-stream", bytes);
    const std::optional<DataUri> back = decode_data_uri(uri);
    ASSERT_TRUE(back);
    EXPECT_EQ(back->bytes, bytes);
    EXPECT_EQ(back->mime_type, "application/octet-stream");
  }
  EXPECT_EQ(encode_data_uri("image/png", "Man"), "data:image/png;base64,TWFu");
  EXPECT_EQ(decode_data_uri("data:image/webp;base64,TWE=")->bytes, "Ma");
  EXPECT_EQ(decode_data_uri("data:image/webp;base64,TWE=")->mime_type, "image/webp");
}

TEST(DataUri, WhatIsNotBase64IsRefused) {
  EXPECT_FALSE(decode_data_uri("file.bin"));
  EXPECT_FALSE(decode_data_uri("data:text/plain,hello"));
  EXPECT_FALSE(decode_data_uri("data:;base64,TW*u"));
  EXPECT_FALSE(decode_data_uri("data:;base64,T"));
  EXPECT_FALSE(decode_data_uri("data:;base64,TW=u"));
}

TEST(Uri, PercentEncodingRoundTrips) {
  EXPECT_EQ(decode_uri("textures/Scene%20-%20Root%5fa.png"), "textures/Scene - Root_a.png");
  EXPECT_EQ(encode_uri("fuze uv.jpg"), "fuze%20uv.jpg");
  EXPECT_EQ(decode_uri(encode_uri("a b/c%d+e.png")), "a b/c%d+e.png");
  EXPECT_EQ(decode_uri("50%"), "50%");  // a lone % is itself
}

}  // namespace
}  // namespace specdeform::detail
