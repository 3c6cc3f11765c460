// Copyright wild_mvs authors.
#include "text_util.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace wild_mvs {
namespace io_detail {

TextFile::TextFile(const std::string& path) : path_(path) {
  Require(!std::filesystem::is_directory(path), path,
          ": is a folder, expected a file");
  in_.open(path, std::ios::binary);
  if (!in_) {
    const int err = errno;
    throw Error(Msg(path, ": cannot open: ", std::strerror(err)));
  }
}

bool TextFile::Next(std::string* line) {
  if (!std::getline(in_, *line)) return false;
  ++line_;
  if (!line->empty() && line->back() == '\r') line->pop_back();
  return true;
}

bool TextFile::NextData(std::string* line) {
  while (Next(line)) {
    const std::string t = Trim(*line);
    if (t.empty() || t[0] == '#') continue;
    return true;
  }
  return false;
}

std::string TextFile::Where() const { return Msg(path_, " line ", line_); }

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream is(line);
  std::string tok;
  while (is >> tok) out.push_back(tok);
  return out;
}

std::string Trim(const std::string& s) {
  const char* ws = " \t\r\n\v\f";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(ws);
  return s.substr(b, e - b + 1);
}

double ParseDouble(const std::string& tok, const std::string& where,
                   const std::string& what) {
  const char* s = tok.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s, &end);
  if (end == s || *end != '\0')
    throw Error(Msg(where, ": ", what, " '", tok, "' is not a number"));
  if (!std::isfinite(v) || errno == ERANGE)
    throw Error(Msg(where, ": ", what, " '", tok,
                    "' is not a finite number (NaN/Inf/overflow)"));
  return v;
}

long long ParseInt(const std::string& tok, const std::string& where,
                   const std::string& what) {
  const char* s = tok.c_str();
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s, &end, 10);
  if (end == s || *end != '\0' || errno == ERANGE)
    throw Error(Msg(where, ": ", what, " '", tok, "' is not an integer"));
  return v;
}

void RequireTokens(const std::vector<std::string>& tokens, size_t n, bool exact,
                   const std::string& where, const std::string& what) {
  if (tokens.size() < n)
    throw Error(Msg(where, ": truncated line: ", what, " needs ", n,
                    " values, found ", tokens.size()));
  if (exact && tokens.size() != n)
    throw Error(Msg(where, ": ", what, " needs exactly ", n, " values, found ",
                    tokens.size()));
}

std::string ReadWholeFile(const std::string& path, size_t max_bytes) {
  std::error_code ec;
  Require(!std::filesystem::is_directory(path, ec), path,
          ": is a folder, expected a file");
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) {
    const int err = errno;
    throw Error(Msg(path, ": cannot open: ", std::strerror(err)));
  }
  const std::streamoff size = in.tellg();
  Require(size >= 0, path, ": cannot determine the file size");
  Require(static_cast<size_t>(size) <= max_bytes, path, ": file is too large (",
          size, " bytes)");
  std::string data(static_cast<size_t>(size), '\0');
  in.seekg(0);
  if (size > 0 && !in.read(&data[0], size))
    throw Error(Msg(path, ": read error"));
  return data;
}

}  // namespace io_detail
}  // namespace wild_mvs
