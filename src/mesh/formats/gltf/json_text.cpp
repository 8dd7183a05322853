#include "json_text.h"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace specdeform::detail {

namespace {

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

// How new text is laid out: the file's indentation unit (empty: compact) and what it writes
// between a key and its value.
struct Layout {
  std::string indent;
  std::string colon = ":";
};

std::string number_text(const Json& v) {
  if (!v.is_number_float()) return v.dump();
  const double d = v.get<double>();
  if (!std::isfinite(d)) return "null";  // as nlohmann writes them: JSON has no NaN
  char buffer[64];
  const float f = static_cast<float>(d);
  const auto end = double(f) == d ? std::to_chars(buffer, buffer + sizeof buffer, f).ptr
                                  : std::to_chars(buffer, buffer + sizeof buffer, d).ptr;
  return std::string(buffer, end);
}

void value_text(const Json& v, const Layout& layout, const std::string& margin, std::string& out) {
  if (!v.is_structured()) {
    out += v.is_number() ? number_text(v) : v.dump();
    return;
  }
  const bool object = v.is_object();
  if (v.empty()) {
    out += object ? "{}" : "[]";
    return;
  }
  const std::string inner = margin + layout.indent;
  out += object ? '{' : '[';
  bool first = true;
  for (auto it = v.begin(); it != v.end(); ++it) {
    if (!first) out += ',';
    first = false;
    if (!layout.indent.empty()) out += "\n" + inner;
    if (object) out += Json(it.key()).dump() + layout.colon;
    value_text(*it, layout, inner, out);
  }
  if (!layout.indent.empty()) out += "\n" + margin;
  out += object ? '}' : ']';
}

// One member or element of a container as the text has it.
struct Item {
  size_t start = 0;  // the key (members) or the value (elements)
  size_t value = 0, end = 0;
  std::string key;
};

class Patcher {
 public:
  explicit Patcher(std::string_view text) : text_(text) {}

  std::string run(const Json& before, const Json& after) {
    size_t pos = text_.starts_with("\xEF\xBB\xBF") ? 3 : 0;
    pos = skip_blanks(pos);
    detect_layout(pos);
    std::string out(text_.substr(0, pos));
    pos = patch(before, after, pos, "", out);
    if (skip_blanks(pos) != text_.size()) mismatch();
    out += text_.substr(pos);
    return out;
  }

 private:
  [[noreturn]] static void mismatch() {
    throw std::logic_error("patch_json_text: the text is not the document it was parsed into");
  }

  size_t skip_blanks(size_t pos) const {
    while (pos < text_.size() && is_blank(text_[pos])) ++pos;
    return pos;
  }

  size_t skip_string(size_t pos) const {
    if (pos >= text_.size() || text_[pos] != '"') mismatch();
    for (++pos; pos < text_.size(); ++pos) {
      if (text_[pos] == '\\') {
        ++pos;
      } else if (text_[pos] == '"') {
        return pos + 1;
      }
    }
    mismatch();
  }

  size_t skip_value(size_t pos) const {
    if (pos >= text_.size()) mismatch();
    if (text_[pos] == '"') return skip_string(pos);
    if (text_[pos] != '{' && text_[pos] != '[') {
      while (pos < text_.size() && !is_blank(text_[pos]) && text_[pos] != ',' &&
             text_[pos] != ']' && text_[pos] != '}')
        ++pos;
      return pos;
    }
    int depth = 0;
    for (; pos < text_.size(); ++pos) {
      const char c = text_[pos];
      if (c == '"') {
        pos = skip_string(pos) - 1;
      } else if (c == '{' || c == '[') {
        ++depth;
      } else if ((c == '}' || c == ']') && --depth == 0) {
        return pos + 1;
      }
    }
    mismatch();
  }

  // The unit of indentation and the key-value separator, from the top level's first member.
  void detect_layout(size_t pos) {
    if (pos >= text_.size() || text_[pos] != '{') return;
    const size_t key = skip_blanks(pos + 1);
    const std::string_view lead = text_.substr(pos + 1, key - pos - 1);
    if (const size_t nl = lead.rfind('\n'); nl != std::string_view::npos) {
      layout_.indent = std::string(lead.substr(nl + 1));
    }
    if (key < text_.size() && text_[key] == '"') {
      const size_t after_key = skip_string(key);
      const size_t colon = text_.find(':', after_key);
      if (colon != std::string_view::npos) {
        layout_.colon = std::string(text_.substr(after_key, skip_blanks(colon + 1) - after_key));
      }
    }
  }

  // The items of the container at `pos` and its end.
  size_t items(size_t pos, bool object, std::vector<Item>& out) const {
    const char close = object ? '}' : ']';
    pos = skip_blanks(pos + 1);
    if (pos < text_.size() && text_[pos] == close) return pos + 1;
    for (;;) {
      Item item;
      item.start = pos;
      if (object) {
        const size_t key_end = skip_string(pos);
        item.key = Json::parse(text_.substr(pos, key_end - pos)).get<std::string>();
        pos = skip_blanks(key_end);
        if (pos >= text_.size() || text_[pos] != ':') mismatch();
        pos = skip_blanks(pos + 1);
      }
      item.value = pos;
      item.end = skip_value(pos);
      out.push_back(std::move(item));
      pos = skip_blanks(out.back().end);
      if (pos < text_.size() && text_[pos] == close) return pos + 1;
      if (pos >= text_.size() || text_[pos] != ',') mismatch();
      pos = skip_blanks(pos + 1);
    }
  }

  size_t patch(const Json& before, const Json& after, size_t pos, const std::string& margin,
               std::string& out) {
    const size_t end = skip_value(pos);
    if (before == after) {
      out += text_.substr(pos, end - pos);
      return end;
    }
    const bool object = before.is_object() && after.is_object();
    if (!object && !(before.is_array() && after.is_array())) {
      value_text(after, layout_, margin, out);
      return end;
    }
    std::vector<Item> old;
    if (items(pos, object, old) != end) mismatch();
    if (old.size() != before.size()) mismatch();
    // The text around the items: before the first, between two, after the last.
    const std::string_view close = text_.substr(end - 1, 1);
    std::string lead, trail;
    std::vector<std::string_view> between;
    if (old.empty()) {
      if (!layout_.indent.empty()) {
        lead = "\n" + margin + layout_.indent;
        trail = "\n" + margin;
      }
    } else {
      lead = text_.substr(pos + 1, old.front().start - pos - 1);
      for (size_t i = 1; i < old.size(); ++i) {
        between.push_back(text_.substr(old[i - 1].end, old[i].start - old[i - 1].end));
      }
      const size_t last = skip_blanks(old.back().end);
      trail = text_.substr(old.back().end, end - 1 - old.back().end);
      if (last != end - 1) mismatch();
    }
    const bool pretty = lead.find('\n') != std::string::npos;
    const std::string inner = pretty ? lead.substr(lead.rfind('\n') + 1) : margin + layout_.indent;
    const Layout layout{pretty ? layout_.indent : std::string(), layout_.colon};
    const std::string usual = between.empty() ? "," + lead : std::string(between.back());

    out += text_[pos];
    bool first = true;
    const auto separate = [&](std::string_view own) {
      out += first ? std::string_view(lead) : own;
      first = false;
    };
    size_t index = 0;
    auto b = before.begin();
    for (size_t i = 0; i < old.size(); ++i, ++b) {
      const Item& item = old[i];
      if (object) {
        if (b.key() != item.key) mismatch();
        const auto a = after.find(item.key);
        if (a == after.end()) continue;
        separate(i > 0 ? between[i - 1] : std::string_view(usual));
        out += text_.substr(item.start, item.value - item.start);
        patch(*b, *a, item.value, inner, out);
      } else {
        if (index >= after.size()) break;
        separate(i > 0 ? between[i - 1] : std::string_view(usual));
        patch(before[index], after[index], item.value, inner, out);
        ++index;
      }
    }
    if (object) {
      for (auto a = after.begin(); a != after.end(); ++a) {
        if (before.contains(a.key())) continue;
        separate(usual);
        out += Json(a.key()).dump() + layout_.colon;
        value_text(*a, layout, inner, out);
      }
    } else {
      for (; index < after.size(); ++index) {
        separate(usual);
        value_text(after[index], layout, inner, out);
      }
    }
    if (!first) out += trail;
    out += close;
    return end;
  }

  std::string_view text_;
  Layout layout_;
};

}  // namespace

std::string patch_json_text(std::string_view text, const Json& before, const Json& after) {
  return Patcher(text).run(before, after);
}

}  // namespace specdeform::detail
