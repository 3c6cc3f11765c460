// Copyright wild_mvs authors. Private helper: bounds-checked little-endian
// reads from an in-memory file, so a truncated or corrupt binary file gives
// an Error naming the file and offset, never a crash or a huge allocation.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace io_detail {

class ByteReader {
 public:
  ByteReader(const std::string& data, const std::string& path)
      : data_(data), path_(path) {}

  size_t offset() const { return pos_; }
  size_t remaining() const { return data_.size() - pos_; }
  bool AtEnd() const { return pos_ >= data_.size(); }
  const std::string& path() const { return path_; }

  template <typename T>
  T Read(const char* what) {
    static_assert(sizeof(T) <= 8, "scalar only");
    if (remaining() < sizeof(T))
      throw Error(Msg(path_, ": truncated file: cannot read ", what,
                      " at byte ", pos_, " (file has ", data_.size(),
                      " bytes)"));
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));  // host is little-endian
    pos_ += sizeof(T);
    return v;
  }
  // Null-terminated string.
  std::string ReadCString(const char* what) {
    const size_t end = data_.find('\0', pos_);
    if (end == std::string::npos)
      throw Error(Msg(path_, ": truncated file: unterminated ", what,
                      " at byte ", pos_));
    std::string s = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return s;
  }
  // Checks that `count` elements of at least `min_bytes_each` can still be
  // present before anything is allocated for them.
  void RequireCount(uint64_t count, uint64_t min_bytes_each,
                    const char* what) const {
    if (min_bytes_each > 0 && count > remaining() / min_bytes_each)
      throw Error(Msg(path_, ": corrupt or truncated file: ", what, " = ",
                      count, " at byte ", pos_, " needs at least ",
                      min_bytes_each, " bytes each but only ", remaining(),
                      " bytes remain"));
  }
  void Skip(size_t n, const char* what) {
    if (remaining() < n)
      throw Error(Msg(path_, ": truncated file: cannot read ", what,
                      " at byte ", pos_));
    pos_ += n;
  }
  const char* Here() const { return data_.data() + pos_; }

 private:
  const std::string& data_;
  std::string path_;
  size_t pos_ = 0;
};

}  // namespace io_detail
}  // namespace wild_mvs
