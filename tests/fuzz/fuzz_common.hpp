// Shared by the fuzz targets of tests/fuzz (docs/fuzzing.md): the readers take file
// paths, so each input is written to a private scratch directory first (in /dev/shm
// when there is one: no disk traffic per input).
#pragma once
#include <stdlib.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "base/errors.hpp"

namespace fdem::fuzz {

// The scratch directory of this process, made on first use and removed at exit.
inline const std::string& scratch_dir() {
  struct Scratch {
    std::string path;
    Scratch() {
      // FDEM_FUZZ_SCRATCH (tests/fuzz/run.sh sets it) holds the directories, so that the
      // ones of crashed processes, which skip this destructor, are removed with it.
      const char* parent = std::getenv("FDEM_FUZZ_SCRATCH");
      const bool shm = std::filesystem::is_directory("/dev/shm") && ::access("/dev/shm", W_OK) == 0;
      path = std::string(parent && *parent ? parent : shm ? "/dev/shm" : "/tmp") + "/fdem-fuzz-XXXXXX";
      if (!::mkdtemp(path.data())) {
        std::perror("fdem fuzz: mkdtemp");
        std::abort();
      }
    }
    ~Scratch() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Scratch scratch;
  return scratch.path;
}

// Writes the input to scratch_dir()/name and returns its path.
inline std::string write_input(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = scratch_dir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::perror(("fdem fuzz: writing " + path).c_str());
    std::abort();
  }
  return path;
}

// No reader may run gmsh or any other program while fuzzing: an empty PATH makes
// io::mesh_geo refuse with its "gmsh is not on PATH" error instead.
inline void no_programs() { ::setenv("PATH", "", 1); }

}  // namespace fdem::fuzz
