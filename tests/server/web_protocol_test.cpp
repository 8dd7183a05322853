// The browser's copy of the protocol (web/src/protocol.ts) against the server's (protocol.h):
// every message tag has the same number on both sides.
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "protocol.h"

namespace specdeform::server {
namespace {

TEST(WebProtocol, TagsMatchTheServers) {
  std::ifstream in(std::string(SPECDEFORM_WEB_SRC) + "/protocol.ts");
  ASSERT_TRUE(in) << "cannot read web/src/protocol.ts";
  std::stringstream text;
  text << in.rdbuf();
  const std::string source = text.str();
  const std::string block = source.substr(source.find("export const Tag = {"));
  std::map<std::string, uint32_t> web;
  const std::regex entry(R"((\w+): (\d+),)");
  for (auto it =
           std::sregex_iterator(block.begin(), block.begin() + block.find("} as const"), entry);
       it != std::sregex_iterator(); ++it) {
    web[(*it)[1]] = static_cast<uint32_t>(std::stoul((*it)[2]));
  }
  const std::map<std::string, Tag> server = {
      {"Selection", Tag::Selection}, {"Frame", Tag::Frame},
      {"MeshFile", Tag::MeshFile},   {"SelectionFile", Tag::SelectionFile},
      {"SceneFile", Tag::SceneFile}, {"CompanionFile", Tag::CompanionFile},
      {"Mesh", Tag::Mesh},           {"FrameResult", Tag::FrameResult},
      {"File", Tag::File},           {"SelectionResult", Tag::SelectionResult},
      {"Preview", Tag::Preview},     {"Appearance", Tag::Appearance},
      {"Texture", Tag::Texture}};
  EXPECT_EQ(web.size(), server.size());
  for (const auto& [name, tag] : server) {
    ASSERT_TRUE(web.count(name)) << name << " is missing from protocol.ts";
    EXPECT_EQ(web[name], static_cast<uint32_t>(tag)) << name;
  }
}

}  // namespace
}  // namespace specdeform::server
