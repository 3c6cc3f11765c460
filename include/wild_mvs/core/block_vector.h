// Copyright wild_mvs authors. An append-only array stored in fixed-size
// blocks: growing it never copies or moves the elements and never holds more
// than one partly filled block, so its memory is the elements plus at most
// one block (a std::vector doubles its capacity, holds up to twice its
// size, and briefly three times its size while it reallocates). Element
// addresses are stable.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

namespace wild_mvs {

// T must be default-constructible and copy-assignable. kBlockBits: log2 of
// the elements per block.
template <typename T, int kBlockBits = 14>
class BlockVector {
 public:
  static constexpr size_t kBlockSize = size_t{1} << kBlockBits;

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T& operator[](size_t i) {
    return blocks_[i >> kBlockBits][i & (kBlockSize - 1)];
  }
  const T& operator[](size_t i) const {
    return blocks_[i >> kBlockBits][i & (kBlockSize - 1)];
  }
  void push_back(const T& value) {
    if ((size_ & (kBlockSize - 1)) == 0 &&
        (size_ >> kBlockBits) == blocks_.size())
      blocks_.push_back(std::make_unique<T[]>(kBlockSize));
    (*this)[size_++] = value;
  }
  // Bytes allocated for the elements and the block table.
  size_t bytes() const {
    return blocks_.size() * kBlockSize * sizeof(T) +
           blocks_.capacity() * sizeof(std::unique_ptr<T[]>);
  }
  void clear() {
    blocks_.clear();
    blocks_.shrink_to_fit();
    size_ = 0;
  }

 private:
  std::vector<std::unique_ptr<T[]>> blocks_;
  size_t size_ = 0;
};

}  // namespace wild_mvs
