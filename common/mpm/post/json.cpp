// The JSON writer of mpm-post's --json output.
#include "mpm/post/json.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace mpm {

void JsonWriter::separate() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (!has_items_.empty()) {
    if (has_items_.back()) text_ += ", ";
    has_items_.back() = true;
  }
}

JsonWriter& JsonWriter::raw(std::string_view value) {
  separate();
  text_ += value;
  return *this;
}

JsonWriter& JsonWriter::open(char bracket) {
  raw(std::string_view(&bracket, 1));
  has_items_.push_back(false);
  return *this;
}

JsonWriter& JsonWriter::close(char bracket) {
  has_items_.pop_back();
  text_ += bracket;
  return *this;
}

JsonWriter& JsonWriter::begin_object() {
  return open('{');
}

JsonWriter& JsonWriter::end_object() {
  return close('}');
}

JsonWriter& JsonWriter::begin_array() {
  return open('[');
}

JsonWriter& JsonWriter::end_array() {
  return close(']');
}

JsonWriter& JsonWriter::key(std::string_view name) {
  string(name);
  text_ += ": ";
  after_key_ = true;
  return *this;
}

JsonWriter& JsonWriter::number(double v) {
  if (!std::isfinite(v)) return raw("null");
  // The shortest text that reads back as the same double: every bit, for scripts that
  // compare runs, and no more digits than that.
  char b[40];
  const auto r = std::to_chars(b, b + sizeof b, v);
  return raw(std::string_view(b, std::size_t(r.ptr - b)));
}

JsonWriter& JsonWriter::boolean(bool v) {
  return raw(v ? "true" : "false");
}

JsonWriter& JsonWriter::string(std::string_view s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\')
      o += '\\', o += c;
    else if (c == '\n')
      o += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20)
      o += ' ';
    else
      o += c;
  }
  return raw(o + "\"");
}

JsonWriter& JsonWriter::numbers(const std::vector<double>& v) {
  begin_array();
  for (double x : v) number(x);
  return end_array();
}

}  // namespace mpm
