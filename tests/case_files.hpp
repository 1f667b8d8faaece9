// Helpers for end-to-end tests: case files in a temporary folder, and reading back
// the Exodus and history files a run wrote.
#pragma once
#include <netcdf.h>

#include <filesystem>
#include <fstream>
#include <cstdlib>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace fdem::test {

// A fresh temporary folder, removed with the object.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    std::random_device rd;
    path = std::filesystem::temp_directory_path() / ("fdem_test_" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const auto p = path / name;
    std::ofstream(p) << text;
    return p.string();
  }
  std::string str() const { return path.string(); }
};

// OCL_ICD_FILENAMES as the test binary found it at start-up ("" when unset). On the GPU
// machine (Ubuntu 24.04) the NVIDIA driver is listed only there, as
// "libpocl.so.2:libnvidia-opencl.so.1", and the fdem processes these tests start saw it cut
// to its first entry (2026-12-02: `fdem run` children of fdem_tests found PoCL alone, and so
// did the ranks of an mpirun there), which points at the loader rewriting the variable once
// it has read it. Read during static initialisation, before any OpenCL call, and given back
// to every child (child_environment, restore_child_environment).
inline const std::string& startup_icd_filenames() {
  static const std::string value = [] {
    const char* v = std::getenv("OCL_ICD_FILENAMES");
    return std::string(v ? v : "");
  }();
  return value;
}
namespace detail {
inline const bool icd_filenames_read = (startup_icd_filenames(), true);
}

// Assignments to put before a shell command that starts a child fdem.
inline std::string child_environment() {
  const std::string& icd = startup_icd_filenames();
  return icd.empty() ? "" : "OCL_ICD_FILENAMES='" + icd + "' ";
}
// In a forked child before exec: the same, for children started without a shell.
inline void restore_child_environment() {
  const std::string& icd = startup_icd_filenames();
  if (!icd.empty()) ::setenv("OCL_ICD_FILENAMES", icd.c_str(), 1);
}

// A file of the source tree; FDEM_SOURCE_DIR in the environment overrides the build's
// (for running the test binary on another machine).
inline std::string source_path(const std::string& relative) {
  const char* env = std::getenv("FDEM_SOURCE_DIR");
  return std::string(env && *env ? env : FDEM_SOURCE_DIR) + "/" + relative;
}

// The text of a case on tests/data/cases/bar.geo (a 1 m × 0.2 m bar; physical groups
// "bar", "left", "right", "top", "bottom") in the end-to-end tests' rock, "rock": ρ 2000
// kg/m³, E 10 GPa, ν 0.2. Each field is the body of its table; `material` adds keys
// (and sub-tables such as [material.fracture]) to the rock, `rest` follows it.
struct BarCase {
  std::string title = "bar";          // no title line when empty
  std::string mesh = "size = 0.05\n";  // [mesh] keys besides geo
  std::string time;
  std::string output;
  std::string material;
  std::string rest;

  std::string text() const {
    return (title.empty() ? "" : "title = \"" + title + "\"\n") + "[mesh]\ngeo = \"" +
           source_path("tests/data/cases/bar.geo") + "\"\n" + mesh + "[time]\n" + time + "[output]\n" + output +
           "[[material]]\nname = \"rock\"\nregions = [\"bar\"]\ndensity = 2000.0\nyoung = 10e9\npoisson = 0.2\n" +
           material + rest;
  }
};

// Reads a netCDF variable (all of it, as doubles) or throws.
inline std::vector<double> read_variable(const std::string& file, const std::string& name) {
  int nc = -1, var = -1, ndims = 0;
  if (nc_open(file.c_str(), NC_NOWRITE, &nc) != NC_NOERR) throw std::runtime_error("cannot open " + file);
  if (nc_inq_varid(nc, name.c_str(), &var) != NC_NOERR) {
    nc_close(nc);
    throw std::runtime_error(file + " has no variable " + name);
  }
  int dims[NC_MAX_VAR_DIMS];
  nc_inq_varndims(nc, var, &ndims);
  nc_inq_vardimid(nc, var, dims);
  size_t count = 1;
  for (int d = 0; d < ndims; ++d) {
    size_t len = 0;
    nc_inq_dimlen(nc, dims[d], &len);
    count *= len;
  }
  std::vector<double> values(count);
  if (count) nc_get_var_double(nc, var, values.data());
  nc_close(nc);
  return values;
}

// One variable of two runs' files, value by value: the rows each has and how many of the
// first min(rows) differ in any bit (restart and determinism tests).
struct VariableDiff {
  size_t rows_a = 0, rows_b = 0, differ = 0;
};
inline VariableDiff compare_variable(const std::string& file_a, const std::string& file_b, const std::string& name) {
  const auto a = read_variable(file_a, name), b = read_variable(file_b, name);
  VariableDiff d{a.size(), b.size(), 0};
  for (size_t k = 0; k < a.size() && k < b.size(); ++k) d.differ += a[k] != b[k];
  return d;
}

// Index (1-based, as in vals_elem_varK) of an Exodus element or nodal variable name.
inline int exodus_variable_index(const std::string& file, const std::string& names_var, const std::string& name) {
  int nc = -1, var = -1;
  if (nc_open(file.c_str(), NC_NOWRITE, &nc) != NC_NOERR) throw std::runtime_error("cannot open " + file);
  nc_inq_varid(nc, names_var.c_str(), &var);
  int dims[2];
  nc_inq_vardimid(nc, var, dims);
  size_t count = 0, length = 0;
  nc_inq_dimlen(nc, dims[0], &count);
  nc_inq_dimlen(nc, dims[1], &length);
  std::vector<char> text(count * length);
  nc_get_var_text(nc, var, text.data());
  nc_close(nc);
  for (size_t k = 0; k < count; ++k)
    if (std::string(text.data() + k * length, strnlen(text.data() + k * length, length)) == name)
      return static_cast<int>(k + 1);
  throw std::runtime_error(file + " has no variable named " + name);
}

// Values of element variable `name` on block `block` (1-based) at the last frame.
inline std::vector<double> last_element_values(const std::string& file, const std::string& name, int block = 1) {
  const int k = exodus_variable_index(file, "name_elem_var", name);
  const auto all = read_variable(file, "vals_elem_var" + std::to_string(k) + "eb" + std::to_string(block));
  const auto times = read_variable(file, "time_whole");
  const size_t per_frame = all.size() / times.size();
  return std::vector<double>(all.end() - per_frame, all.end());
}

}  // namespace fdem::test
