// A JSON text edited in place (mesh/formats/gltf/json_text.h): what did not change keeps its
// bytes, what changed is laid out as its neighbours are.
#include "mesh/formats/gltf/json_text.h"

#include <gtest/gtest.h>

namespace specdeform::detail {
namespace {

// Blender's layout: four spaces, "key" : value, arrays one element per line.
const std::string kPretty = R"({
    "asset" : {
        "generator" : "Khronos glTF Blender I/O v3.4.50",
        "version" : "2.0"
    },
    "accessors" : [
        {
            "bufferView" : 0,
            "componentType" : 5126,
            "count" : 24,
            "max" : [
                1.0000001,
                1,
                1E0
            ],
            "min" : [
                -1,
                -1,
                -1
            ],
            "type" : "VEC3"
        }
    ],
    "extras" : {"note" : "caf\u00e9"},
    "nodes" : []
}
)";

TEST(JsonText, UnchangedIsTheSameText) {
  for (const std::string& text : {kPretty, std::string(R"({"a":[1,2.50,3e2],"b":{"c":"\"x\""}})"),
                                  std::string("\xEF\xBB\xBF{ \"a\" : 1 }\n\n")}) {
    const Json parsed = Json::parse(text);
    EXPECT_EQ(patch_json_text(text, parsed, parsed), text);
  }
}

TEST(JsonText, ChangedNumbersAloneAreRewritten) {
  const Json before = Json::parse(kPretty);
  Json after = before;
  after["accessors"][0]["max"][0] = double(0.1f);  // a float32 value: its shortest float text
  after["accessors"][0]["min"][2] = 0.1;           // a double: its shortest double text
  const std::string out = patch_json_text(kPretty, before, after);
  std::string expected = kPretty;
  expected.replace(expected.find("1.0000001"), 9, "0.1");
  expected.replace(expected.rfind("-1\n"), 2, "0.1");
  EXPECT_EQ(out, expected);
  EXPECT_EQ(Json::parse(out)["accessors"][0]["max"][0].get<float>(), 0.1f);  // reads back
}

TEST(JsonText, AddedAndRemovedMembersFollowTheirNeighbours) {
  const Json before = Json::parse(kPretty);
  Json after = before;
  after["accessors"].push_back({{"bufferView", 3}, {"count", 2}, {"min", {0.5, 2}}});
  after["nodes"].push_back({{"mesh", 1}});
  after["asset"].erase("generator");
  after["scene"] = 0;
  const std::string out = patch_json_text(kPretty, before, after);
  EXPECT_EQ(Json::parse(out), after);
  // The new accessor is indented as the first, a member per line, "key" : value.
  EXPECT_NE(
      out.find(
          "        },\n        {\n            \"bufferView\" : 3,\n            \"count\" : 2,\n"
          "            \"min\" : [\n                0.5,\n                2\n"),
      std::string::npos)
      << out;
  EXPECT_NE(out.find("    \"nodes\" : [\n        {\n            \"mesh\" : 1\n        }\n    ],\n"
                     "    \"scene\" : 0\n}\n"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("\"asset\" : {\n        \"version\" : \"2.0\"\n    },"), std::string::npos)
      << out;
  // Untouched members keep their text, escapes included.
  EXPECT_NE(out.find(R"("extras" : {"note" : "caf\u00e9"})"), std::string::npos);
}

TEST(JsonText, CompactStaysCompact) {
  const std::string text = R"({"buffers":[{"byteLength":8}],"meshes":[]})";
  const Json before = Json::parse(text);
  Json after = before;
  after["buffers"][0]["byteLength"] = 16;
  after["buffers"][0]["uri"] = "a b.bin";
  after["meshes"].push_back({{"primitives", Json::array()}});
  after["buffers"].erase(0);
  after["buffers"].push_back({{"byteLength", 4}});
  EXPECT_EQ(patch_json_text(text, before, after),
            R"({"buffers":[{"byteLength":4}],"meshes":[{"primitives":[]}]})");
}

TEST(JsonText, TextThatIsNotTheDocumentIsRefused) {
  EXPECT_THROW(patch_json_text(R"({"a":1})", Json::parse(R"({"b":1})"), Json::parse(R"({"b":2})")),
               std::logic_error);
  EXPECT_THROW(
      patch_json_text(R"({"a":[1,2]})", Json::parse(R"({"a":[1]})"), Json::parse(R"({"a":[3]})")),
      std::logic_error);
}

}  // namespace
}  // namespace specdeform::detail
