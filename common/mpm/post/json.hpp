#pragma once
/// The small JSON writer of mpm-post's --json output: objects and arrays on one line, members
/// separated by ", " and keys by ": ", numbers in %.10g (null when not finite), strings escaped.
#include <concepts>
#include <string>
#include <string_view>
#include <vector>

namespace mpm {

/// Builds one JSON text. In an object each value follows a key(); in an array values follow
/// one another. The caller balances begin_ and end_ calls.
class JsonWriter {
 public:
  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  /// The name of the next member of the current object.
  JsonWriter& key(std::string_view name);
  /// A floating value in %.10g; null when not finite (JSON has no inf or nan).
  JsonWriter& number(double v);
  /// An integer in full.
  template <std::integral T>
  JsonWriter& integer(T v) {
    return raw(std::to_string(v));
  }
  JsonWriter& boolean(bool v);
  /// A string: quotes and backslashes escaped, newlines as \n, other control characters as
  /// spaces.
  JsonWriter& string(std::string_view s);
  /// An array of number()s.
  JsonWriter& numbers(const std::vector<double>& v);
  /// The text written so far.
  const std::string& text() const { return text_; }

 private:
  /// Writes a value's text after the separator its place needs.
  JsonWriter& raw(std::string_view value);
  void separate();
  /// Starts a container with its opening bracket; close() ends it.
  JsonWriter& open(char bracket);
  JsonWriter& close(char bracket);

  std::string text_;
  std::vector<bool> has_items_;  ///< per open container: whether it holds an item yet
  bool after_key_ = false;       ///< a key was written and waits for its value
};

}  // namespace mpm
