// The bytes of a Gmsh file in memory, read as ASCII tokens or raw binary values with
// messages that name the file and the line (ASCII) or byte offset (binary).
#pragma once
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include "base/errors.hpp"

namespace fdem::io {

// The whole of a file as bytes; throws InputError naming the file and `what` it should
// be ("Gmsh mesh file", ".geo file") when it is missing, a directory or unreadable.
std::string read_file_bytes(const std::string& path, const char* what);

// A Gmsh file's bytes in memory with a read position. ASCII tokens and binary values are
// read from the same buffer because binary MSH files interleave ASCII header lines with
// raw data.
class MshBuffer {
 public:
  MshBuffer(std::string path, std::string bytes) : path_(std::move(path)), text_(std::move(bytes)) {}

  bool binary = false;
  bool swap_bytes = false;
  int size_t_bytes = 8;
  std::string section;  // current section name, for messages

  const std::string& path() const { return path_; }
  size_t pos() const { return pos_; }
  // Start of the next item, for messages. Binary data must not be skipped as whitespace.
  size_t mark() {
    if (!binary) skip_space();
    return pos_;
  }

  [[noreturn]] void fail(const std::string& what) const { fail_at(pos_, what); }
  [[noreturn]] void fail_at(size_t at, const std::string& what) const {
    std::string where;
    if (binary)
      where = "byte " + std::to_string(at);
    else
      where = "line " + std::to_string(1 + std::count(text_.begin(), text_.begin() + std::min(at, text_.size()), '\n'));
    if (!section.empty()) where += " ($" + section + ")";
    throw InputError(path_ + ": " + where + ": " + what);
  }

  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  bool at_end() {
    skip_space();
    return pos_ >= text_.size();
  }

  std::string token(const char* what) {
    skip_space();
    if (pos_ >= text_.size()) fail(std::string("unexpected end of file, expected ") + what + " (file truncated?)");
    size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    return text_.substr(start, pos_ - start);
  }

  // Numbers are parsed in place (the buffer is NUL-terminated) to avoid a string per
  // value; a number must end at whitespace or at the end of the file.
  long long ascii_int(const char* what) {
    skip_space();
    const char* start = text_.c_str() + pos_;
    char* end = nullptr;
    errno = 0;
    long long v = std::strtoll(start, &end, 10);
    if (!number_ended(start, end) || errno != 0) not_a_number(what, "an integer");
    pos_ += static_cast<size_t>(end - start);
    return v;
  }

  double ascii_real(const char* what) {
    skip_space();
    const char* start = text_.c_str() + pos_;
    char* end = nullptr;
    double v = std::strtod(start, &end);
    if (!number_ended(start, end) || !std::isfinite(v)) not_a_number(what, "a number");
    pos_ += static_cast<size_t>(end - start);
    return v;
  }

  // Rest of the current line without its line end; used for section headers and for
  // stepping over ASCII element lines of types we skip.
  std::string rest_of_line() {
    size_t end = text_.find('\n', pos_);
    if (end == std::string::npos) end = text_.size();
    std::string line = text_.substr(pos_, end - pos_);
    pos_ = std::min(end + 1, text_.size());
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    return line;
  }

  std::string next_line() {
    skip_space();
    return rest_of_line();
  }

  // Binary data starts right after the '\n' of the preceding ASCII line; skipping all
  // whitespace would eat data bytes such as 0x0a or 0x20.
  void end_ascii_line() { rest_of_line(); }

  std::string quoted(const char* what) {
    skip_space();
    if (pos_ >= text_.size() || text_[pos_] != '"') fail(std::string("expected ") + what + " in double quotes");
    size_t close = text_.find('"', pos_ + 1);
    size_t eol = text_.find('\n', pos_);
    if (close == std::string::npos || (eol != std::string::npos && close > eol)) fail(std::string("unterminated quoted ") + what);
    std::string s = text_.substr(pos_ + 1, close - pos_ - 1);
    pos_ = close + 1;
    return s;
  }

  template <class T>
  T raw(const char* what) {
    if (pos_ + sizeof(T) > text_.size()) fail(std::string("unexpected end of file reading ") + what + " (file truncated?)");
    unsigned char b[sizeof(T)];
    std::memcpy(b, text_.data() + pos_, sizeof(T));
    if (swap_bytes) std::reverse(b, b + sizeof(T));
    T v;
    std::memcpy(&v, b, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }

  // "int" fields of the format: 4-byte int in binary files.
  long long get_int(const char* what) { return binary ? raw<int32_t>(what) : ascii_int(what); }
  double get_real(const char* what) {
    if (!binary) return ascii_real(what);
    double v = raw<double>(what);
    if (!std::isfinite(v)) fail_at(pos_ - 8, std::string(what) + " is not a finite number");
    return v;
  }
  // "size_t" fields of MSH 4.1: data-size bytes in binary files. Also used for counts,
  // which are bounded by the file size so that a corrupt count cannot allocate wildly.
  long long get_size(const char* what) {
    long long v = !binary ? ascii_int(what) : size_t_bytes == 8 ? static_cast<long long>(raw<uint64_t>(what)) : raw<uint32_t>(what);
    if (v < 0) fail(std::string(what) + " is negative");
    return v;
  }
  long long get_count(long long value_of, const char* what) {
    if (value_of > static_cast<long long>(text_.size())) fail(std::string(what) + " " + std::to_string(value_of) + " exceeds what the file can hold (corrupt or truncated)");
    return value_of;
  }

  void expect_end(const std::string& name) {
    skip_space();
    size_t at = pos_;
    std::string line = pos_ < text_.size() ? rest_of_line() : std::string();
    if (line != "$End" + name) {
      if (line.empty()) fail_at(at, "missing $End" + name + " (file truncated?)");
      fail_at(at, "expected $End" + name + ", found '" + line.substr(0, 40) + "'");
    }
    section.clear();
  }

  void skip_section(const std::string& name) {
    size_t end = text_.find("$End" + name, pos_);
    if (end == std::string::npos) fail("missing $End" + name + " (file truncated?)");
    pos_ = end;
    rest_of_line();
    section.clear();
  }

 private:
  bool number_ended(const char* start, const char* end) const {
    return end != start && (*end == '\0' || std::isspace(static_cast<unsigned char>(*end)));
  }
  [[noreturn]] void not_a_number(const char* what, const char* kind) {
    size_t at = pos_;
    std::string found = token(what);
    fail_at(at, std::string("expected ") + what + " (" + kind + "), found '" + found.substr(0, 40) + "'");
  }

  std::string path_;
  std::string text_;
  size_t pos_ = 0;
};

}  // namespace fdem::io
