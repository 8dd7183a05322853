// The materials an OBJ's MTL files define (obj.h).
#include <charconv>
#include <filesystem>

#include "mesh/polygon_soup.h"
#include "obj.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

std::string_view trimmed(std::string_view s) {
  const size_t first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

// The first word of `s` and the rest after the blanks that follow it.
std::pair<std::string_view, std::string_view> first_word(std::string_view s) {
  const size_t end = std::min(s.find_first_of(" \t"), s.size());
  return {s.substr(0, end), trimmed(s.substr(end))};
}

bool is_number(std::string_view t) {
  double v;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return ec == std::errc() && end == t.data() + t.size();
}

bool is_texture_statement(std::string_view key) {
  return key.starts_with("map_") || key == "bump" || key == "disp" || key == "decal" ||
         key == "refl" || key == "norm";
}

}  // namespace

MtlTexture mtl_texture(std::string_view rest) {
  // Options with a fixed count of words, and -o, -s and -t with one to three numbers.
  static constexpr std::pair<std::string_view, int> kOptions[] = {
      {"-blendu", 1}, {"-blendv", 1},  {"-bm", 1}, {"-boost", 1},  {"-cc", 1},
      {"-clamp", 1},  {"-imfchan", 1}, {"-mm", 2}, {"-texres", 1}, {"-type", 1},
      {"-o", -3},     {"-s", -3},      {"-t", -3}};
  MtlTexture out;
  Eigen::Matrix<float, 2, 3>& transform = out.sampling.transform;  // (u s_u + o_u, v s_v + o_v)
  rest = trimmed(rest);
  for (;;) {
    const auto [first, after] = first_word(rest);
    const std::string_view word = first;  // a binding a lambda can take
    const auto option = std::find_if(std::begin(kOptions), std::end(kOptions),
                                     [&](const auto& o) { return o.first == word; });
    if (option == std::end(kOptions)) break;
    rest = after;
    for (int k = 0; k < std::abs(option->second) && !rest.empty(); ++k) {
      const auto [value, next] = first_word(rest);
      if (option->second < 0 && !is_number(value)) break;  // -s u [v [w]]
      rest = next;
      float v = 0;
      std::from_chars(value.data(), value.data() + value.size(), v);
      if (word == "-clamp" && value == "on") {
        out.sampling.wrap_u = out.sampling.wrap_v = TextureSampling::Wrap::Clamp;
      } else if (word == "-s" && k < 2) {
        transform(k, k) = v;
      } else if (word == "-o" && k < 2) {
        transform(k, 2) = v;
      }
    }
  }
  out.name = rest;
  std::replace(out.name.begin(), out.name.end(), '\\', '/');  // written on Windows
  return out;
}

void read_obj_materials(KeptRecord& record, const FileResolver& companions) {
  ObjLayout& layout = std::get<ObjLayout>(record.layout.format);
  std::vector<Material>& materials = record.attributes.materials;
  if (!companions) return;
  for (const std::string& library : layout.mtllib) {
    std::optional<std::string> text;
    try {
      text = companions(library);
    } catch (const InputError&) {
      continue;  // a name the resolver refuses: plain materials
    }
    if (!text) continue;
    const std::filesystem::path folder = std::filesystem::path(library).parent_path();
    Material* current = nullptr;
    for (size_t at = 0; at < text->size();) {
      size_t end = text->find('\n', at);
      if (end == std::string::npos) end = text->size();
      const auto [key, rest] = first_word(trimmed(std::string_view(*text).substr(at, end - at)));
      at = end + 1;
      if (key == "newmtl") {
        current = nullptr;
        for (Material& m : materials)
          if (m.name == rest) current = &m;
      } else if (current && key == "Kd") {
        std::string_view values = rest;
        for (int k = 0; k < 3 && !values.empty(); ++k) {
          const auto [t, next] = first_word(values);
          double v = 1;
          std::from_chars(t.data(), t.data() + t.size(), v);
          current->base_color[k] = static_cast<float>(v);
          values = next;
        }
      } else if (is_texture_statement(key)) {
        const MtlTexture texture = mtl_texture(rest);
        if (texture.name.empty()) continue;
        const std::string path = (folder / texture.name).lexically_normal().generic_string();
        layout.textures.push_back(path);
        if (current && key == "map_Kd") {
          current->texture = path;
          current->sampling = texture.sampling;
        }
      }
    }
  }
}

}  // namespace specdeform::detail
