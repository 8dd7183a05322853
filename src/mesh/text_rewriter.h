// Internal: a text file copied with some of its numbers replaced (the same-format writers of
// the text formats). Tokens are separated by blanks, line ends and '#' comments (to the line's
// end), as the text readers (TextScanner) read them.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace specdeform::detail {

enum class NumberText {
  Float,    // the shortest text that reads back to the same float32
  Double,   // the shortest text that reads back to the same double
  Integer,  // rounded to the nearest integer
};

// A token as the text readers read it (a leading '+' allowed); NaN for anything else.
double read_number(std::string_view token);

class TextRewriter {
 public:
  // Rewrites source from `begin` on (the text before it is not copied).
  explicit TextRewriter(std::string_view source, size_t begin = 0);

  // Copies the source up to `offset` (not before the current position).
  void seek(size_t offset);
  // The next token (after blanks) without moving; empty at the end.
  std::string_view peek() const;
  // Copies the next `count` tokens and the blanks before them.
  void keep(long long count);
  // Copies the blanks, then writes `value` in place of the next token, or the token itself where
  // it reads back as `value` written in `style`.
  void replace(double value, NumberText style);
  size_t position() const { return pos_; }
  // Double where any of the `count` tokens from any of `offsets` has more than 9 significant
  // digits (a file written in double precision), else Float (written from single precision,
  // as most are): how the file's new positions are written.
  NumberText precision(const std::vector<size_t>& offsets, int count) const;
  // The source up to `end` appended; the text.
  std::string finish(size_t end = std::string_view::npos);

 private:
  size_t token_start(size_t from) const;
  size_t token_end(size_t start) const;

  std::string_view source_;
  size_t pos_ = 0;
  std::string out_;
};

// The source with its numbers rewritten by `part(out, from, to)`, which seeks and replaces those
// at offsets in [from, to): a large text in two halves at once, split at a line.
std::string rewrite_text(std::string_view source,
                         const std::function<void(TextRewriter&, size_t, size_t)>& part);

}  // namespace specdeform::detail
