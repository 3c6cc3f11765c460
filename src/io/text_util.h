// Copyright wild_mvs authors. Private helpers of the text readers: line
// reading with line numbers and strict number parsing (rejects NaN, Inf,
// trailing garbage), so every error names the file and the line.
#pragma once

#include <fstream>
#include <string>
#include <vector>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace io_detail {

class TextFile {
 public:
  // Throws Error naming `path` when it cannot be opened.
  explicit TextFile(const std::string& path);
  // Next raw line (without the newline / CR); false at end of file.
  bool Next(std::string* line);
  // Next line that is neither empty nor a '#' comment.
  bool NextData(std::string* line);
  int line() const { return line_; }
  const std::string& path() const { return path_; }
  // "path line N" for messages.
  std::string Where() const;

 private:
  std::string path_;
  std::ifstream in_;
  int line_ = 0;
};

// Splits on whitespace.
std::vector<std::string> Split(const std::string& line);
// Trims whitespace on both ends.
std::string Trim(const std::string& s);

// Parse a finite number / integer; throws Error "<where>: <what> '<tok>' is
// not a finite number".
double ParseDouble(const std::string& tok, const std::string& where,
                   const std::string& what);
long long ParseInt(const std::string& tok, const std::string& where,
                   const std::string& what);

// Throws unless tokens.size() >= n (or == n when exact).
void RequireTokens(const std::vector<std::string>& tokens, size_t n, bool exact,
                   const std::string& where, const std::string& what);

// Whole file into memory (binary); throws Error naming the path. Refuses
// files larger than max_bytes.
std::string ReadWholeFile(const std::string& path, size_t max_bytes = size_t(1)
                                                                      << 34);

}  // namespace io_detail
}  // namespace wild_mvs
