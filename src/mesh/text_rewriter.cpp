#include "text_rewriter.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "linalg/parallel.h"

namespace specdeform::detail {

namespace {

bool is_blank(char c) {  // as the text readers' (TextScanner)
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

int significant_digits(std::string_view t) {
  int digits = 0;
  bool leading = true;
  for (const char c : t) {
    if (c == 'e' || c == 'E') break;
    if (c < '0' || c > '9') continue;
    if (c != '0') leading = false;
    if (!leading) ++digits;
  }
  return digits;
}

}  // namespace

double read_number(std::string_view token) {
  double v = std::nan("");
  const char* begin = token.data() + (token.starts_with('+') ? 1 : 0);
  std::from_chars(begin, token.data() + token.size(), v);
  return v;
}

TextRewriter::TextRewriter(std::string_view source, size_t begin) : source_(source), pos_(begin) {
  const size_t size = source.size() - begin;
  out_.reserve(size + size / 4);
}

void TextRewriter::seek(size_t offset) {
  if (offset <= pos_) return;
  out_.append(source_.substr(pos_, offset - pos_));
  pos_ = offset;
}

size_t TextRewriter::token_start(size_t from) const {
  size_t p = from;
  while (p < source_.size()) {
    if (is_blank(source_[p])) {
      ++p;
    } else if (source_[p] == '#') {  // a comment, to the line's end, as the readers skip it
      while (p < source_.size() && source_[p] != '\n') ++p;
    } else {
      break;
    }
  }
  return p;
}

size_t TextRewriter::token_end(size_t start) const {
  size_t p = start;
  while (p < source_.size() && !is_blank(source_[p]) && source_[p] != '#') ++p;
  return p;
}

std::string_view TextRewriter::peek() const {
  const size_t start = token_start(pos_);
  return source_.substr(start, token_end(start) - start);
}

void TextRewriter::keep(long long count) {
  size_t p = pos_;
  for (long long k = 0; k < count; ++k) p = token_end(token_start(p));
  seek(p);
}

void TextRewriter::replace(double value, NumberText style) {
  const size_t start = token_start(pos_);
  seek(start);
  const size_t end = token_end(start);
  const std::string_view token = source_.substr(start, end - start);
  const double old = read_number(token);
  char buf[40];
  std::to_chars_result written{};
  // The token stays where it reads back as the value (exactly, or in its style's precision).
  bool same = value == old || (std::isnan(value) && std::isnan(old));
  switch (style) {
    case NumberText::Float:
      same = same || static_cast<float>(value) == static_cast<float>(old);
      written = std::to_chars(buf, buf + sizeof buf, static_cast<float>(value));
      break;
    case NumberText::Integer:
      same = same || std::llround(value) == old;
      written = std::to_chars(buf, buf + sizeof buf, std::llround(value));
      break;
    default:
      written = std::to_chars(buf, buf + sizeof buf, value);
  }
  if (same) {
    out_.append(token);
  } else {
    out_.append(buf, written.ptr);
  }
  pos_ = end;
}

NumberText TextRewriter::precision(const std::vector<size_t>& offsets, int count) const {
  for (const size_t offset : offsets) {
    size_t p = offset;
    for (int k = 0; k < count; ++k) {
      const size_t start = token_start(p);
      p = token_end(start);
      if (significant_digits(source_.substr(start, p - start)) > 9) return NumberText::Double;
    }
  }
  return NumberText::Float;
}

std::string TextRewriter::finish(size_t end) {
  seek(std::min(end, source_.size()));
  return std::move(out_);
}

std::string rewrite_text(std::string_view source,
                         const std::function<void(TextRewriter&, size_t, size_t)>& part) {
  constexpr size_t kSplitFrom = 8 << 20;  // bytes
  const size_t split =
      source.size() < kSplitFrom ? std::string_view::npos : source.find('\n', source.size() / 2);
  if (split == std::string_view::npos) {
    TextRewriter out(source);
    part(out, 0, source.size());
    return out.finish();
  }
  std::string first, second;
  bool crossed = false;  // a number of the first half stood after the split (a line continued)
  run_pair(
      [&] {
        TextRewriter out(source);
        part(out, 0, split + 1);
        crossed = out.position() > split + 1;
        first = out.finish(split + 1);
      },
      [&] {
        TextRewriter out(source, split + 1);
        part(out, split + 1, source.size());
        second = out.finish();
      });
  if (crossed) {
    TextRewriter out(source);
    part(out, 0, source.size());
    return out.finish();
  }
  first += second;
  return first;
}

}  // namespace specdeform::detail
