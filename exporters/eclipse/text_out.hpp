// Fast text building for the ASCII exporters: shortest round-trip numbers (std::to_chars, so a
// double read back is bit-identical), Eclipse arrays with `N*value` run-length compression.
#pragma once
#include <charconv>
#include <cstdint>
#include <string>
#include <vector>

namespace hm {

class TextOut {
 public:
  std::string text;

  TextOut& operator<<(const std::string& s) { text += s; return *this; }
  TextOut& operator<<(const char* s) { text += s; return *this; }
  TextOut& operator<<(char c) { text += c; return *this; }
  TextOut& operator<<(int v) { return integer(v); }
  TextOut& operator<<(long v) { return integer(v); }
  TextOut& operator<<(long long v) { return integer(v); }
  TextOut& operator<<(unsigned long v) { return integer(static_cast<long long>(v)); }
  TextOut& operator<<(double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    text.append(buf, r.ptr);
    return *this;
  }

  /// An Eclipse array keyword: KEYWORD, the values (equal runs as `N*value`), `/`.
  template <class T>
  void eclipse_array(const char* keyword, const std::vector<T>& values) {
    *this << keyword << '\n';
    size_t on_line = 0;
    for (size_t i = 0; i < values.size();) {
      size_t j = i + 1;
      while (j < values.size() && values[j] == values[i]) ++j;
      if (j - i > 1) *this << static_cast<long long>(j - i) << '*';
      *this << values[i];
      if (++on_line == 8) {
        text += '\n';
        on_line = 0;
      } else {
        text += ' ';
      }
      i = j;
    }
    text += "/\n\n";
  }

 private:
  template <class I>
  TextOut& integer(I v) {
    char buf[24];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    text.append(buf, r.ptr);
    return *this;
  }
};

}  // namespace hm
