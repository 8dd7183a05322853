// Internal: a small line-aware tokenizer for the text formats (OBJ, OFF, ASCII PLY/STL, and the
// scenes' .sel, .dmat and .def files).
#pragma once

#include <charconv>
#include <string>
#include <string_view>

#include "specdeform/exceptions.h"

namespace specdeform::detail {

class TextScanner {
 public:
  TextScanner(std::string_view data, std::string name) : data_(data), name_(std::move(name)) {}

  // Next whitespace-separated token; with skip_comments, '#' starts a comment up to the line end.
  // Returns an empty view at the end of the data.
  std::string_view next(bool skip_comments = true) {
    while (pos_ < data_.size()) {
      const char c = data_[pos_];
      if (c == '#' && skip_comments) {
        while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
      } else if (is_space(c)) {
        ++pos_;
      } else {
        break;
      }
    }
    const size_t start = pos_;
    while (pos_ < data_.size() && !is_space(data_[pos_]) && !(skip_comments && data_[pos_] == '#'))
      ++pos_;
    return data_.substr(start, pos_ - start);
  }

  // Skips the rest of the current line.
  void skip_line() {
    while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
    if (pos_ < data_.size()) ++pos_;
  }

  // True if only blanks remain before the end of the current line (comments count as blank).
  bool at_line_end() const {
    size_t p = pos_;
    while (p < data_.size() && data_[p] != '\n' &&
           (data_[p] == ' ' || data_[p] == '\t' || data_[p] == '\r'))
      ++p;
    return p >= data_.size() || data_[p] == '\n' || data_[p] == '#';
  }

  double next_double(const char* what) { return to_double(next(), what); }
  long long next_integer(const char* what) { return to_integer(next(), what); }

  // A token from next() as a number or an integer; fail()s naming `what` for anything else (an
  // empty token means the data ended).
  double to_double(std::string_view t, const char* what) const {
    return parse<double>(t, what, "number");
  }
  long long to_integer(std::string_view t, const char* what) const {
    return parse<long long>(t, what, "integer");
  }

  size_t position() const { return pos_; }
  void set_position(size_t pos) { pos_ = pos; }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(name_ + ": " + what); }

 private:
  template <typename T>
  T parse(std::string_view t, const char* what, const char* kind) const {
    if (t.empty()) fail(std::string("unexpected end of file while reading ") + what);
    const char* begin = t.data();
    if (*begin == '+') ++begin;
    T v{};
    const auto [end, ec] = std::from_chars(begin, t.data() + t.size(), v);
    if (ec != std::errc() || end != t.data() + t.size()) {
      fail("bad " + std::string(kind) + " '" + std::string(t.substr(0, 32)) + "' in " + what);
    }
    return v;
  }
  static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  }
  std::string_view data_;
  std::string name_;
  size_t pos_ = 0;
};

// The small text file Git LFS leaves in place of a file it has not fetched: InputError
// "<name>: is a Git LFS pointer, not the <what>: run git lfs pull".
inline void reject_git_lfs_pointer(std::string_view data, const std::string& name,
                                   const char* what) {
  if (data.starts_with("version https://git-lfs.github.com/spec/")) {
    throw InputError(name + ": is a Git LFS pointer, not the " + what + ": run git lfs pull");
  }
}

}  // namespace specdeform::detail
