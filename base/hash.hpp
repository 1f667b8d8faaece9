// FNV-1a, 64 bit: the one hash the project uses for names and integrity checks (the .geo
// mesh cache, the mesh hash and the checksum of checkpoints). Not cryptographic.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace fdem {

class Fnv1a {
 public:
  void add(const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) hash_ = (hash_ ^ p[k]) * 1099511628211ull;
  }
  void add(const std::string& text) { add(text.data(), text.size()); }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 1469598103934665603ull;
};

inline std::uint64_t fnv1a(const std::string& text) {
  Fnv1a h;
  h.add(text);
  return h.value();
}

}  // namespace fdem
