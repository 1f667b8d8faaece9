#include "engine/device/checkpoint.hpp"

#include <cstring>
#include <vector>

#include "base/errors.hpp"
#include "engine/device/device_arrays.hpp"

namespace fdem {

template <typename T>
void StateWriter::buffer(const std::string& name, const compute::buffer& b, size_t items, size_t width) {
  io::CheckpointArray a{name, array_type<T>(), width, {}};
  a.bytes.resize(items * width * sizeof(T));
  if (!a.bytes.empty()) cl_.queue().enqueue_read_buffer(b, 0, a.bytes.size(), a.bytes.data());
  data_.arrays.push_back(std::move(a));
}

template <typename T>
void StateWriter::host(const std::string& name, const T* values, size_t count, size_t width) {
  io::CheckpointArray a{name, array_type<T>(), width, {}};
  a.bytes.resize(count * width * sizeof(T));
  if (count) std::memcpy(a.bytes.data(), values, a.bytes.size());
  data_.arrays.push_back(std::move(a));
}

void StateWriter::group_slots(const std::string& name, const compute::buffer& b, size_t groups, size_t width) {
  buffer<real>(name, b, groups, width);
  integer(name + "_group_size", static_cast<std::int64_t>(cl_.group_size()));
}

const io::CheckpointArray& StateReader::array(const std::string& name, io::ArrayType type, size_t items,
                                              size_t width) const {
  const auto* a = data_.find(name);
  if (!a) throw InputError("checkpoint '" + path_ + "' has no '" + name + "' (written by another version, or damaged)");
  if (a->type != type || a->width != width || a->items() != items)
    throw InputError("checkpoint '" + path_ + "': '" + name + "' holds " + std::to_string(a->items()) + " × " +
                     std::to_string(a->width) + " values, this run needs " + std::to_string(items) + " × " +
                     std::to_string(width) + (a->type != type ? " of another type" : "") +
                     " (another mesh or case?)");
  return *a;
}

template <typename T>
void StateReader::buffer(const std::string& name, compute::buffer& b, size_t items, size_t width) {
  const auto& a = array(name, array_type<T>(), items, width);
  if (!a.bytes.empty()) cl_.queue().enqueue_write_buffer(b, 0, a.bytes.size(), a.bytes.data());
}

template <typename T>
void StateReader::host(const std::string& name, T* values, size_t count, size_t width) {
  const auto& a = array(name, array_type<T>(), count, width);
  if (count) std::memcpy(values, a.bytes.data(), a.bytes.size());
}

void StateReader::group_slots(const std::string& name, compute::buffer& b, size_t groups, size_t width) {
  const auto* a = data_.find(name);
  if (!a) throw InputError("checkpoint '" + path_ + "' has no '" + name + "'");
  if (a->items() == groups && a->width == width && a->type == array_type<real>()) {
    buffer<real>(name, b, groups, width);
    return;
  }
  if (a->type != array_type<real>() || a->width != width)
    throw InputError("checkpoint '" + path_ + "': '" + name + "' has another layout");
  std::vector<real> in(a->items() * width), out(groups * width, real(0));
  std::memcpy(in.data(), a->bytes.data(), a->bytes.size());
  for (size_t g = 0; g < a->items(); ++g)
    for (size_t k = 0; k < width; ++k) out[k] += in[g * width + k];
  upload(cl_, b, out);
}

std::int64_t StateReader::integer(const std::string& name) const {
  const auto it = data_.integers.find(name);
  if (it == data_.integers.end()) throw InputError("checkpoint '" + path_ + "' has no '" + name + "'");
  return it->second;
}

double StateReader::number(const std::string& name) const {
  const auto it = data_.numbers.find(name);
  if (it == data_.numbers.end()) throw InputError("checkpoint '" + path_ + "' has no '" + name + "'");
  return it->second;
}

#define FDEM_STATE_TYPES(X) X(double) X(float) X(cl_int) X(cl_uint) X(cl_long) X(cl_ulong) X(cl_uchar)
#define FDEM_INSTANTIATE(T)                                                                                   \
  template void StateWriter::buffer<T>(const std::string&, const compute::buffer&, size_t, size_t);          \
  template void StateWriter::host<T>(const std::string&, const T*, size_t, size_t);                          \
  template void StateReader::buffer<T>(const std::string&, compute::buffer&, size_t, size_t);                \
  template void StateReader::host<T>(const std::string&, T*, size_t, size_t);
FDEM_STATE_TYPES(FDEM_INSTANTIATE)

}  // namespace fdem
