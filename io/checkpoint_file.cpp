#include "io/checkpoint_file.hpp"
#include "io/netcdf_header.hpp"

#include <fcntl.h>
#include <netcdf.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "base/errors.hpp"
#include "base/hash.hpp"

namespace fdem::io {

namespace {

constexpr const char* kMagic = "fdem-cl checkpoint";

nc_type nc_type_of(ArrayType t) {
  switch (t) {
    case ArrayType::Float64: return NC_DOUBLE;
    case ArrayType::Float32: return NC_FLOAT;
    case ArrayType::Int32: return NC_INT;
    case ArrayType::UInt32: return NC_UINT;
    case ArrayType::Int64: return NC_INT64;
    case ArrayType::UInt64: return NC_UINT64;
    case ArrayType::UInt8: return NC_UBYTE;
  }
  return NC_NAT;
}

bool array_type_of(nc_type t, ArrayType& out) {
  switch (t) {
    case NC_DOUBLE: out = ArrayType::Float64; return true;
    case NC_FLOAT: out = ArrayType::Float32; return true;
    case NC_INT: out = ArrayType::Int32; return true;
    case NC_UINT: out = ArrayType::UInt32; return true;
    case NC_INT64: out = ArrayType::Int64; return true;
    case NC_UINT64: out = ArrayType::UInt64; return true;
    case NC_UBYTE: out = ArrayType::UInt8; return true;
    default: return false;
  }
}

// A netCDF handle closed on every path out (the constructor's failures included).
struct Handle {
  int id = -1;
  ~Handle() {
    if (id >= 0) nc_close(id);
  }
};

// The integrity check: a digest (FNV-1a) of every global attribute and every array, kind,
// name, type and value, listed in the text attribute `checksums` ("<16 hex digits> att
// NAME" / "<16 hex digits> var NAME" lines). The reader recomputes each one and refuses the
// file naming the first attribute or array that is missing, added or different: a header
// edited by a netCDF tool (an attribute such as `step` changed, or a `history` attribute
// added) is refused like damaged data.
constexpr const char* kChecksums = "checksums";

std::uint64_t text_digest(const std::string& name, const std::string& value) {
  Fnv1a h;
  h.add("text " + name + '\0');
  h.add(value);
  return h.value();
}

std::uint64_t number_digest(const std::string& name, double value) {
  Fnv1a h;
  h.add("number " + name + '\0');
  h.add(&value, sizeof value);
  return h.value();
}

std::uint64_t integer_digest(const std::string& name, std::int64_t value) {
  Fnv1a h;
  h.add("integer " + name + '\0');
  h.add(&value, sizeof value);
  return h.value();
}

std::uint64_t array_digest(const CheckpointArray& a) {
  Fnv1a h;
  h.add("array " + a.name + '\0');
  const std::uint64_t shape[3] = {static_cast<std::uint64_t>(a.type), a.width, a.items()};
  h.add(shape, sizeof shape);
  h.add(a.bytes.data(), a.bytes.size());
  return h.value();
}

std::string hex(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

// Every item the reader takes from the file, by the name it has there ("att NAME" for a
// global attribute, an empty array's "empty NAME" attribute included; "var NAME" for an
// array), with its digest.
std::map<std::string, std::uint64_t> digests(const CheckpointData& data) {
  std::map<std::string, std::uint64_t> out;
  for (const auto& [k, v] : data.text)
    if (k != kChecksums) out["att " + k] = text_digest(k, v);
  for (const auto& [k, v] : data.numbers) out["att " + k] = number_digest(k, v);
  for (const auto& [k, v] : data.integers) out["att " + k] = integer_digest(k, v);
  for (const auto& a : data.arrays) out[(a.items() == 0 ? "att empty " : "var ") + a.name] = array_digest(a);
  return out;
}

std::string checksums_text(const CheckpointData& data) {
  std::string out;
  for (const auto& [item, digest] : digests(data)) out += hex(digest) + " " + item + "\n";
  return out;
}

}  // namespace

std::size_t element_bytes(ArrayType type) {
  switch (type) {
    case ArrayType::Float64: case ArrayType::Int64: case ArrayType::UInt64: return 8;
    case ArrayType::Float32: case ArrayType::Int32: case ArrayType::UInt32: return 4;
    case ArrayType::UInt8: return 1;
  }
  return 1;
}

const CheckpointArray* CheckpointData::find(const std::string& name) const {
  for (const auto& a : arrays)
    if (a.name == name) return &a;
  return nullptr;
}

void write_checkpoint_file(const std::string& path, const CheckpointData& data) {
  const std::string tmp = path + ".tmp";
  auto fail = [&](int status, const std::string& what) {
    if (status != NC_NOERR) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);  // the previous checkpoint stays as it was
      throw OutputError("checkpoint '" + path + "': " + nc_strerror(status) + " (" + what + ")");
    }
  };
  {
    Handle nc;
    fail(nc_create(tmp.c_str(), NC_CLOBBER | NC_64BIT_DATA, &nc.id), "creating " + tmp);
    int old_fill = 0;
    fail(nc_set_fill(nc.id, NC_NOFILL, &old_fill), "setting fill mode");
    auto text = [&](const std::string& name, const std::string& value) {
      fail(nc_put_att_text(nc.id, NC_GLOBAL, name.c_str(), value.size(), value.c_str()), "attribute " + name);
    };
    CheckpointData stamped = data;
    stamped.text["format"] = kMagic;
    stamped.text.erase(kChecksums);
    text(kChecksums, checksums_text(stamped));
    for (const auto& [k, v] : stamped.text) text(k, v);
    for (const auto& [k, v] : data.numbers)
      fail(nc_put_att_double(nc.id, NC_GLOBAL, k.c_str(), NC_DOUBLE, 1, &v), "attribute " + k);
    for (const auto& [k, v] : data.integers) {
      const long long value = v;
      fail(nc_put_att_longlong(nc.id, NC_GLOBAL, k.c_str(), NC_INT64, 1, &value), "attribute " + k);
    }
    std::vector<int> ids;
    for (const auto& a : data.arrays) {
      if (a.items() == 0) {
        // netCDF takes a dimension of length 0 for the unlimited one: an empty array is
        // recorded by its width and type alone.
        const long long shape[2] = {static_cast<long long>(a.width), static_cast<long long>(a.type)};
        fail(nc_put_att_longlong(nc.id, NC_GLOBAL, ("empty " + a.name).c_str(), NC_INT64, 2, shape), "empty " + a.name);
        ids.push_back(-1);
        continue;
      }
      int dims[2];
      fail(nc_def_dim(nc.id, (a.name + "_items").c_str(), a.items(), &dims[0]), "dimension of " + a.name);
      fail(nc_def_dim(nc.id, (a.name + "_width").c_str(), a.width, &dims[1]), "dimension of " + a.name);
      int id = -1;
      fail(nc_def_var(nc.id, a.name.c_str(), nc_type_of(a.type), 2, dims, &id), "variable " + a.name);
      ids.push_back(id);
    }
    fail(nc_enddef(nc.id), "header");
    for (size_t k = 0; k < data.arrays.size(); ++k)
      if (ids[k] >= 0)
        fail(nc_put_var(nc.id, ids[k], data.arrays[k].bytes.data()), "writing " + data.arrays[k].name);
    fail(nc_close(nc.id), "closing " + tmp);
    nc.id = -1;
  }
  // Data on the disk before the rename makes it visible.
  const int fd = ::open(tmp.c_str(), O_RDONLY);
  if (fd < 0 || ::fsync(fd) != 0) {
    if (fd >= 0) ::close(fd);
    throw OutputError("checkpoint '" + path + "': cannot sync " + tmp);
  }
  ::close(fd);
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) std::filesystem::rename(path, path + ".prev", ec);
  if (ec) throw OutputError("checkpoint '" + path + "': cannot keep the previous one as " + path + ".prev: " + ec.message());
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw OutputError("checkpoint '" + path + "': cannot rename " + tmp + ": " + ec.message());
}

CheckpointData read_checkpoint_file(const std::string& path) {
  auto bad = [&](const std::string& why) { return InputError("checkpoint '" + path + "': " + why); };
  if (!std::filesystem::is_regular_file(path)) throw bad("no such file");
  {
    // libnetcdf trusts the lengths in a header: a damaged or tampered one can make nc_open
    // allocate gigabytes or corrupt memory. The header is checked against the file first
    // (a checkpoint's header is a few kB; 16 MiB are read at most).
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    std::ifstream in(path, std::ios::binary);
    std::string head(static_cast<size_t>(std::min<uint64_t>(ec ? 0 : size, 16u << 20)), '\0');
    if (ec || !in.read(head.data(), static_cast<std::streamsize>(head.size())))
      throw bad("cannot be read");
    CdfHeader header(head, size);
    if (!header.fits())
      throw bad("not a readable netCDF file (its header is damaged, claims more than the file holds, or is not "
                "netCDF classic); truncated, tampered or not a checkpoint");
    if (header.version() != 5) throw bad("not a checkpoint: netCDF classic format " + std::to_string(header.version()) +
                                         ", where checkpoints are CDF-5 (64-bit data)");
  }
  Handle nc;
  if (int s = nc_open(path.c_str(), NC_NOWRITE, &nc.id); s != NC_NOERR)
    throw bad(std::string("not a readable netCDF file (") + nc_strerror(s) + "); truncated or not a checkpoint");
  CheckpointData data;
  int natts = 0, nvars = 0;
  if (nc_inq_natts(nc.id, &natts) != NC_NOERR || nc_inq_nvars(nc.id, &nvars) != NC_NOERR) throw bad("unreadable header");
  // Every attribute is one the writer makes (text, one double, one 64-bit integer, an
  // empty array's shape): anything else was added by another tool, and refused below as
  // not covered by the checksums.
  std::vector<std::string> foreign;
  for (int k = 0; k < natts; ++k) {
    char name[NC_MAX_NAME + 1];
    nc_type type;
    size_t len = 0;
    if (nc_inq_attname(nc.id, NC_GLOBAL, k, name) != NC_NOERR || nc_inq_att(nc.id, NC_GLOBAL, name, &type, &len) != NC_NOERR)
      throw bad("unreadable attribute");
    const auto unreadable = [&] { return bad(std::string("attribute '") + name + "' cannot be read; the file is damaged"); };
    if (type == NC_CHAR) {
      std::string value(len, '\0');
      if (len && nc_get_att_text(nc.id, NC_GLOBAL, name, value.data()) != NC_NOERR) throw unreadable();
      data.text[name] = value;
    } else if (type == NC_DOUBLE && len == 1) {
      if (nc_get_att_double(nc.id, NC_GLOBAL, name, &data.numbers[name]) != NC_NOERR) throw unreadable();
    } else if (type == NC_INT64 && len == 2 && std::string(name).rfind("empty ", 0) == 0) {
      long long shape[2] = {0, 0};
      if (nc_get_att_longlong(nc.id, NC_GLOBAL, name, shape) != NC_NOERR) throw unreadable();
      CheckpointArray a;
      a.name = std::string(name).substr(6);
      a.width = static_cast<size_t>(shape[0]);
      if (!array_type_of(nc_type_of(static_cast<ArrayType>(shape[1])), a.type) || shape[0] < 0)
        throw bad(std::string("attribute '") + name + "' does not describe an empty array");
      data.arrays.push_back(std::move(a));
    } else if (type == NC_INT64 && len == 1) {
      long long value = 0;
      if (nc_get_att_longlong(nc.id, NC_GLOBAL, name, &value) != NC_NOERR) throw unreadable();
      data.integers[name] = value;
    } else {
      foreign.push_back(name);
    }
  }
  if (data.text["format"] != kMagic) throw bad("not an fdem-cl checkpoint (no 'format = " + std::string(kMagic) + "')");
  if (!data.text.count(kChecksums))
    throw bad("it has no 'checksums' attribute: written by an fdem before 2026-12-03 (format version 6 or older), "
              "whose checksum left the attributes out; continue that run with the fdem that wrote it, or start it again");
  for (int v = 0; v < nvars; ++v) {
    char name[NC_MAX_NAME + 1];
    nc_type type;
    int ndims = 0, dims[NC_MAX_VAR_DIMS];
    if (nc_inq_var(nc.id, v, name, &type, &ndims, dims, nullptr) != NC_NOERR || ndims != 2) throw bad("unreadable variable");
    CheckpointArray a;
    a.name = name;
    if (!array_type_of(type, a.type)) throw bad(std::string("variable ") + name + " has an unknown type");
    size_t items = 0, width = 0;
    nc_inq_dimlen(nc.id, dims[0], &items);
    nc_inq_dimlen(nc.id, dims[1], &width);
    a.width = width;
    a.bytes.resize(items * width * element_bytes(a.type));
    if (!a.bytes.empty())
      if (int s = nc_get_var(nc.id, v, a.bytes.data()); s != NC_NOERR)
        throw bad(std::string("cannot read ") + name + " (" + nc_strerror(s) + "); the file is truncated or damaged");
    data.arrays.push_back(std::move(a));
  }
  // The digests written with the file against those of what was read, item by item.
  std::map<std::string, std::uint64_t> written;
  {
    const std::string& list = data.text[kChecksums];
    size_t at = 0;
    while (at < list.size()) {
      const size_t end = std::min(list.find('\n', at), list.size());
      const std::string line = list.substr(at, end - at);
      at = end + 1;
      char* stop = nullptr;
      const unsigned long long digest = line.size() > 17 ? std::strtoull(line.c_str(), &stop, 16) : 0;
      if (line.size() <= 17 || stop != line.c_str() + 16 || line[16] != ' ')
        throw bad("its 'checksums' attribute is damaged (line '" + line + "')");
      written[line.substr(17)] = digest;
    }
  }
  auto what = [](const std::string& item) {
    return item.rfind("var ", 0) == 0 ? "array '" + item.substr(4) + "'" : "attribute '" + item.substr(4) + "'";
  };
  for (const auto& name : foreign)
    throw bad("attribute '" + name + "' is not one fdem writes and not covered by the checksums: the file was edited");
  const auto read = digests(data);
  for (const auto& [item, digest] : read) {
    const auto it = written.find(item);
    if (it == written.end())
      throw bad(what(item) + " is not covered by the checksums: it was added after the file was written");
    if (it->second != digest)
      throw bad(what(item) + " does not match its checksum: the file was edited, damaged or cut short");
  }
  for (const auto& [item, digest] : written)
    if (!read.count(item)) throw bad(what(item) + " is missing: the file was edited, damaged or cut short");
  return data;
}

}  // namespace fdem::io
