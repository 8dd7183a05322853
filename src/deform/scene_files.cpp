// The benchmark's selection and transform files: .sel, .dmat and .def (scene.h).
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "mesh/text_scanner.h"
#include "scene_internal.h"
#include "specdeform/deform/scene.h"

namespace specdeform {

namespace {

void check_count(long long got, int expected, std::string_view name) {
  if (got != expected) {
    throw InputError(std::string(name) + ": " + std::to_string(got) +
                     " vertex entries, the mesh has " + std::to_string(expected) + " vertices");
  }
}

bool is_number(std::string_view t) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return !t.empty() && ec == std::errc() && end == t.data() + t.size();
}

}  // namespace

namespace detail {

std::string read_scene_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path.string() + ": is a directory");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot open file");
  std::ostringstream s;
  s << file.rdbuf();
  if (file.bad()) throw InputError(path.string() + ": read error");
  std::string text = std::move(s).str();
  reject_git_lfs_pointer(text, path.string(), "scene file");
  return text;
}

}  // namespace detail

Selection parse_sel(std::string_view text, int file_vertices, std::string_view name) {
  detail::TextScanner in(text, std::string(name));
  Selection s;
  s.handles.resize(1);
  int i = 0;
  for (std::string_view t = in.next(); !t.empty(); t = in.next(), ++i) {
    const long long status = in.to_integer(t, "a vertex status");
    if (status == 0) {
      s.fixed.push_back(i);
    } else if (status == 2) {
      s.handles[0].push_back(i);
    } else if (status != 1) {
      in.fail("status " + std::to_string(status) + " of vertex " + std::to_string(i) +
              " is not 0 (fixed), 1 (free) or 2 (handle)");
    }
  }
  check_count(i, file_vertices, name);
  return s;
}

Selection parse_dmat(std::string_view text, int file_vertices, std::string_view name) {
  detail::TextScanner in(text, std::string(name));
  const std::string_view first = in.next();
  if (first.empty()) in.fail("not a .dmat file (no 'cols rows' header)");
  const long long cols = in.to_integer(first, "the 'cols rows' header");
  const long long rows = in.next_integer("the 'cols rows' header");
  if (cols != 1 || rows < 0) {
    in.fail("expected one column of per-vertex values, got " + std::to_string(cols) + " x " +
            std::to_string(rows));
  }
  if (rows != file_vertices) check_count(rows, file_vertices, name);
  Selection s;
  int i = 0;
  for (std::string_view t = in.next(); !t.empty(); t = in.next(), ++i) {
    const long long g = in.to_integer(t, "a vertex's group");
    if (g < -1 || g > 1000) {
      in.fail("group " + std::to_string(g) + " of vertex " + std::to_string(i) +
              " is not -1 (free) or a group number");
    }
    if (g < 0) continue;
    if (static_cast<size_t>(g) >= s.handles.size()) s.handles.resize(g + 1);
    s.handles[g].push_back(i);
  }
  check_count(i, file_vertices, name);
  return s;
}

std::vector<Eigen::Affine3d> parse_def(std::string_view text, std::string_view name) {
  detail::TextScanner in(text, std::string(name));
  // The first line is a comment, with or without '#'.
  const size_t start = in.position();
  const bool numbers_first = is_number(in.next());
  in.set_position(start);
  if (!numbers_first) in.skip_line();
  std::vector<double> values;
  for (std::string_view t = in.next(); !t.empty(); t = in.next()) {
    values.push_back(in.to_double(t, "a transform"));
    if (!std::isfinite(values.back())) {
      in.fail("'" + std::string(t.substr(0, 32)) + "' is not a finite number");
    }
  }
  if (values.empty() || values.size() % 16 != 0) {
    in.fail("expected 4 x 4 matrices (16 numbers each), got " + std::to_string(values.size()) +
            " numbers");
  }
  std::vector<Eigen::Affine3d> out;
  for (size_t k = 0; k < values.size(); k += 16) {
    const Eigen::Matrix4d m =
        Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(values.data() + k);
    out.push_back(
        checked_transform(m, std::string(name) + " (matrix " + std::to_string(k / 16) + ")"));
  }
  return out;
}

Selection read_sel(const std::filesystem::path& path, int file_vertices) {
  return parse_sel(detail::read_scene_file(path), file_vertices, path.string());
}

Selection read_dmat(const std::filesystem::path& path, int file_vertices) {
  return parse_dmat(detail::read_scene_file(path), file_vertices, path.string());
}

std::vector<Eigen::Affine3d> read_def(const std::filesystem::path& path) {
  return parse_def(detail::read_scene_file(path), path.string());
}

}  // namespace specdeform
