// Checkpoint files: a self-describing netCDF file (CDF-5, which holds 64-bit integers) of
// named arrays and text/number attributes. Written under a temporary name, synced and
// renamed, so a crash never leaves a half-written checkpoint; the previous one is kept as
// PATH.prev. The engine decides what goes in (engine/device/checkpoint.*).
#pragma once
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace fdem::io {

// What a checkpoint array holds; the file stores it as the matching netCDF type.
enum class ArrayType { Float64, Float32, Int32, UInt32, Int64, UInt64, UInt8 };
std::size_t element_bytes(ArrayType type);

struct CheckpointArray {
  std::string name;
  ArrayType type = ArrayType::Float64;
  std::size_t width = 1;            // values per item (2 for a real2 array)
  std::vector<unsigned char> bytes;  // count × width values of `type`, host byte order
  std::size_t items() const { return width ? bytes.size() / (element_bytes(type) * width) : 0; }
};

struct CheckpointData {
  std::map<std::string, std::string> text;   // global text attributes
  std::map<std::string, double> numbers;     // global double attributes
  std::map<std::string, std::int64_t> integers;  // global 64-bit integer attributes (steps)
  std::vector<CheckpointArray> arrays;
  const CheckpointArray* find(const std::string& name) const;
};

// Writes `data` to PATH.tmp, syncs it (fsync), keeps an existing PATH as PATH.prev and
// renames PATH.tmp to PATH. Throws OutputError naming the path (a full disk included).
void write_checkpoint_file(const std::string& path, const CheckpointData& data);

// Reads a checkpoint back. Throws InputError naming the path for a file that is missing,
// not netCDF, truncated or not an fdem-cl checkpoint.
CheckpointData read_checkpoint_file(const std::string& path);

}  // namespace fdem::io
