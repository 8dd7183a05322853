// Internal: what the writers of a file in another format than its own, or of a mesh made in
// memory, share (mesh_writers.h): numbers as text, little-endian binary values, lines encoded
// on two threads, and the file's polygons as triangles.
#pragma once

#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "linalg/parallel.h"
#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

inline void append_number(std::string& s, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  s.append(buf, end);
}

inline void append_number(std::string& s, float v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, end);
}

inline void append_number(std::string& s, int v) {
  char buf[16];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, end);
}

template <typename T>
void append_le(std::string& s, T v) {
  static_assert(std::endian::native == std::endian::little, "writers assume a little-endian host");
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  s.append(b, sizeof(T));
}

// Lines i = 0 .. count - 1 encoded in two halves at once, one on each thread (692k vertices,
// OBJ: 0.41 -> 0.2-0.26 s with the write). `bytes`: the usual line's length, reserved (a string
// that regrows holds two copies for a moment).
template <typename Line>
std::vector<std::string> lines_in_halves(int count, size_t bytes, const Line& line) {
  std::vector<std::string> part(2);
  const auto encode = [&](int half) {
    const int begin = half * (count / 2), end = half == 0 ? count / 2 : count;
    part[half].reserve(static_cast<size_t>(end - begin) * bytes);
    for (int i = begin; i < end; ++i) line(part[half], i);
  };
  run_pair([&] { encode(0); }, [&] { encode(1); });
  return part;
}

// The corners of polygon p's fan triangles: (0, k, k + 1).
template <typename Visit>
void for_each_triangle(const FileAttributes& a, const Visit& visit) {
  for (int p = 0; p < a.num_polygons(); ++p) {
    const int first = a.offsets[p];
    for (int k = first + 1; k + 1 < a.offsets[p + 1]; ++k) visit(p, first, k, k + 1);
  }
}

// The parts appended to `to`.
void append_parts(std::vector<std::string>& to, std::vector<std::string>&& parts);
// One row per vertex where every corner of the vertex uses the same row (-1: none of its
// corners has one); empty where some vertex's corners use different rows.
std::vector<int> per_vertex(const FileAttributes& a, const std::vector<int>& rows, int vertices);
int count_triangles(const FileAttributes& a);
bool has_polygons(const FileAttributes& a);  // any polygon of more than 3 corners
uint8_t to_byte(float c);                    // a colour in [0, 1] as 0 .. 255

// The file's name without its folder, and its stem (for companions).
struct Target {
  std::string name, stem;
};

// A file in parts to be concatenated (a large one is written part by part), the companions it
// made, the files it names as they are (EncodedMesh::companions) and what it dropped.
struct Encoded {
  std::vector<std::string> parts;
  std::vector<OutputFile> companions;
  std::vector<std::string> kept;
  std::vector<std::string> notes;
};

}  // namespace specdeform::detail
