// A structural check of a classic netCDF header (CDF-1, CDF-2, CDF-5: the format
// checkpoints are written in) against the file it is in: every count, name and attribute
// value must fit in the header bytes given, and every variable's data (its dimensions'
// product times its type's size) in the file. libnetcdf 4.9.0 (Debian 12) trusts these
// lengths: a header that claims more than the file holds makes nc_open allocate what it
// claims (gigabytes) or memcpy with a negative size (heap corruption, abort), see
// docs/fuzzing.md "Findings". The checkpoint reader (io/checkpoint_file.cpp) refuses a
// file whose header does not pass before it calls nc_open.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace fdem::io {

class CdfHeader {
 public:
  // `bytes`: the file's first bytes (all of it, or at least its header); `file_size`: the
  // whole file's (0: bytes.size()).
  explicit CdfHeader(const std::string& bytes, uint64_t file_size = 0)
      : b_(bytes), file_size_(file_size ? file_size : bytes.size()) {}
  int version() const { return version_; }

  // True when the header is well formed and within the file.
  bool fits() {
    if (b_.size() < 4 || b_.compare(0, 3, "CDF") != 0) return false;
    version_ = static_cast<unsigned char>(b_[3]);
    if (version_ != 1 && version_ != 2 && version_ != 5) return false;
    pos_ = 4;
    uint64_t numrecs;
    if (!count(numrecs)) return false;
    uint64_t ndims = 0;
    if (!list(0x0A, ndims, [&] {
          uint64_t length;
          if (!name() || !count(length)) return false;
          dims_.push_back(length == 0 ? numrecs : length);  // 0: the record dimension
          return true;
        }))
      return false;
    uint64_t unused;
    if (!list(0x0C, unused, [&] { return attribute(); })) return false;
    return list(0x0B, unused, [&] {
      uint64_t rank;
      if (!name() || !count(rank) || rank > remaining()) return false;
      uint64_t values = 1;
      for (uint64_t k = 0; k < rank; ++k) {
        uint64_t dim;
        if (!count(dim) || dim >= dims_.size()) return false;
        if (dims_[dim] != 0 && values > file_size_ / dims_[dim]) return false;
        values *= dims_[dim];
      }
      uint64_t attributes;
      if (!list(0x0C, attributes, [&] { return attribute(); })) return false;
      uint32_t type;
      uint64_t vsize, begin;
      return u32(type) && type_size(type) > 0 && values <= file_size_ / type_size(type) && count(vsize) &&
             (version_ == 1 ? u32_as_64(begin) : u64(begin));
    });
  }

 private:
  uint64_t remaining() const { return b_.size() - pos_; }
  bool u32(uint32_t& v) {
    if (remaining() < 4) return false;
    v = 0;
    for (int k = 0; k < 4; ++k) v = v << 8 | static_cast<unsigned char>(b_[pos_++]);
    return true;
  }
  bool u64(uint64_t& v) {
    if (remaining() < 8) return false;
    v = 0;
    for (int k = 0; k < 8; ++k) v = v << 8 | static_cast<unsigned char>(b_[pos_++]);
    return true;
  }
  bool u32_as_64(uint64_t& v) {
    uint32_t w;
    if (!u32(w)) return false;
    v = w;
    return true;
  }
  // Counts and lengths: 32-bit in CDF-1 and CDF-2, 64-bit in CDF-5.
  bool count(uint64_t& v) { return version_ == 5 ? u64(v) : u32_as_64(v); }
  bool skip_padded(uint64_t bytes) {
    const uint64_t padded = (bytes + 3) / 4 * 4;
    if (bytes > remaining() || padded > remaining()) return false;
    pos_ += padded;
    return true;
  }
  bool name() {
    uint64_t length;
    return count(length) && length > 0 && skip_padded(length);
  }
  int type_size(uint32_t type) const {
    static const int sizes[] = {0, 1, 1, 2, 4, 4, 8, 1, 2, 4, 8, 8};
    if (type == 0 || type > 11 || (type > 6 && version_ != 5)) return 0;
    return sizes[type];
  }
  bool attribute() {
    uint32_t type;
    uint64_t values;
    if (!name() || !u32(type) || !count(values)) return false;
    const int size = type_size(type);
    return size > 0 && values <= remaining() && skip_padded(values * static_cast<uint64_t>(size));
  }
  // ABSENT (a zero tag and a zero count) or the tag, a count and that many items, each
  // at least one byte (so a count cannot exceed the bytes left).
  template <class Item>
  bool list(uint32_t tag, uint64_t& items, Item item) {
    uint32_t t;
    if (!u32(t) || !count(items)) return false;
    if (t == 0) return items == 0;
    if (t != tag || items > remaining()) return false;
    for (uint64_t k = 0; k < items; ++k)
      if (!item()) return false;
    return true;
  }

  const std::string& b_;
  uint64_t file_size_;
  std::vector<uint64_t> dims_;  // dimension lengths (the record dimension's: numrecs)
  uint64_t pos_ = 0;
  int version_ = 0;
};

}  // namespace fdem::io
