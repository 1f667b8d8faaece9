// Moving the run's state between the device and a checkpoint (io/checkpoint_file.*): each
// stage saves and loads its own arrays by name through these two helpers.
#pragma once
#include <cstdint>
#include <string>

#include "engine/device/cl_context.hpp"
#include "engine/model/real.hpp"
#include "io/checkpoint_file.hpp"

namespace fdem {

template <typename T> io::ArrayType array_type();
template <> inline io::ArrayType array_type<double>() { return io::ArrayType::Float64; }
template <> inline io::ArrayType array_type<float>() { return io::ArrayType::Float32; }
template <> inline io::ArrayType array_type<cl_int>() { return io::ArrayType::Int32; }
template <> inline io::ArrayType array_type<cl_uint>() { return io::ArrayType::UInt32; }
template <> inline io::ArrayType array_type<cl_long>() { return io::ArrayType::Int64; }
template <> inline io::ArrayType array_type<cl_ulong>() { return io::ArrayType::UInt64; }
template <> inline io::ArrayType array_type<cl_uchar>() { return io::ArrayType::UInt8; }

class StateWriter {
 public:
  StateWriter(ClContext& cl, io::CheckpointData& data) : cl_(cl), data_(data) {}
  // `items` × `width` values of T from the start of `buffer` (waits for the queue).
  template <typename T>
  void buffer(const std::string& name, const compute::buffer& buffer, size_t items, size_t width = 1);
  // Per-work-group sums (cumulative energy terms): saved with the group size they were
  // made with, so a restart on another device can fold them (see StateReader).
  void group_slots(const std::string& name, const compute::buffer& buffer, size_t groups, size_t width);
  // `count` × `width` values of T from the host (as buffer() writes a device array).
  template <typename T>
  void host(const std::string& name, const T* values, size_t count, size_t width = 1);
  void integer(const std::string& name, std::int64_t value) { data_.integers[name] = value; }
  void number(const std::string& name, double value) { data_.numbers[name] = value; }

 private:
  ClContext& cl_;
  io::CheckpointData& data_;
};

class StateReader {
 public:
  StateReader(ClContext& cl, const io::CheckpointData& data, const std::string& path)
      : cl_(cl), data_(data), path_(path) {}
  // Loads the named array into `buffer`; InputError when it is missing or its size or
  // type differs from `items` × `width` values of T.
  template <typename T>
  void buffer(const std::string& name, compute::buffer& buffer, size_t items, size_t width = 1);
  // Loads per-work-group sums: as they are when the group count matches, else the sum of
  // all groups goes to group 0 (the totals are kept; a checkpoint moves between devices).
  void group_slots(const std::string& name, compute::buffer& buffer, size_t groups, size_t width);
  template <typename T>
  void host(const std::string& name, T* values, size_t count, size_t width = 1);
  std::int64_t integer(const std::string& name) const;
  double number(const std::string& name) const;
  bool has(const std::string& name) const { return data_.find(name) != nullptr; }  // an array
  bool has_number(const std::string& name) const { return data_.numbers.count(name) != 0; }

 private:
  const io::CheckpointArray& array(const std::string& name, io::ArrayType type, size_t items, size_t width) const;
  ClContext& cl_;
  const io::CheckpointData& data_;
  std::string path_;
};

}  // namespace fdem
