// Internal: a small line-aware tokenizer for the ASCII mesh formats (OFF, ASCII PLY/STL).
#pragma once

#include <charconv>
#include <optional>
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

  double next_double(const char* what) {
    const std::string_view t = next();
    double v = 0.0;
    if (t.empty()) fail(std::string("unexpected end of file while reading ") + what);
    const char* begin = t.data();
    if (*begin == '+') ++begin;
    const auto [end, ec] = std::from_chars(begin, t.data() + t.size(), v);
    if (ec != std::errc() || end != t.data() + t.size()) {
      fail(std::string("bad number '") + std::string(t.substr(0, 32)) + "' in " + what);
    }
    return v;
  }

  long long next_integer(const char* what) {
    const std::string_view t = next();
    long long v = 0;
    if (t.empty()) fail(std::string("unexpected end of file while reading ") + what);
    const char* begin = t.data();
    if (*begin == '+') ++begin;
    const auto [end, ec] = std::from_chars(begin, t.data() + t.size(), v);
    if (ec != std::errc() || end != t.data() + t.size()) {
      fail(std::string("bad integer '") + std::string(t.substr(0, 32)) + "' in " + what);
    }
    return v;
  }

  size_t position() const { return pos_; }
  void set_position(size_t pos) { pos_ = pos; }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(name_ + ": " + what); }

 private:
  static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  }
  std::string_view data_;
  std::string name_;
  size_t pos_ = 0;
};

}  // namespace specdeform::detail
