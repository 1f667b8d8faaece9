// The committed meshes of the tests' .geo files (tests/data/meshes): this test binary,
// and the fdem processes its tests start, look a .geo's mesh up there before running
// gmsh (FDEM_MESH_CACHE_RO, io/gmsh_reader.hpp), so that the whole suite runs where
// gmsh is missing (the GPU machine; tools/gpu-suite). tools/gpu-suite --refresh-meshes
// remakes them and their MANIFEST; the test below says when a .geo changed since.
#include <doctest/doctest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "base/hash.hpp"
#include "case_files.hpp"

namespace {

std::string committed_dir() { return fdem::test::source_path("tests/data/meshes"); }

// At start-up, before any test: FDEM_MESH_CACHE_RO gains the committed folder. Set in
// the environment already (even empty, as --refresh-meshes does), it is left alone.
const bool committed_meshes_on = [] {
  if (std::getenv("FDEM_MESH_CACHE_RO")) return false;
  ::setenv("FDEM_MESH_CACHE_RO", committed_dir().c_str(), 1);
  return true;
}();

std::string read_text(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace

TEST_SUITE("gmsh") {

TEST_CASE("every committed mesh is listed in the MANIFEST and still matches its .geo and size") {
  namespace fs = std::filesystem;
  const fs::path dir = committed_dir();
  REQUIRE(fs::is_regular_file(dir / "MANIFEST"));
  std::ifstream manifest(dir / "MANIFEST");
  std::string line;
  std::set<std::string> listed;
  int entries = 0;
  while (std::getline(manifest, line)) {
    if (line.empty() || line[0] == '#') continue;
    CAPTURE(line);
    std::istringstream fields(line);
    std::string name, size_text, geo, escaped, suffix;
    REQUIRE(std::getline(fields, name, '\t'));
    REQUIRE(std::getline(fields, size_text, '\t'));
    REQUIRE(std::getline(fields, geo, '\t'));
    // A fourth field: what the name hashes beside the .geo and the size (the algorithm,
    // text appended to the .geo such as embedded joints), \\, \n and \t escaped.
    std::getline(fields, escaped);
    for (size_t k = 0; k < escaped.size(); ++k) {
      if (escaped[k] == '\\' && k + 1 < escaped.size()) {
        const char next = escaped[++k];
        suffix += next == 'n' ? '\n' : next == 't' ? '\t' : next;
      } else {
        suffix += escaped[k];
      }
    }
    ++entries;
    listed.insert(name);
    CHECK(fs::is_regular_file(dir / name));
    if (geo == "(written by a test)") continue;  // its text is in the test's source
    const fs::path geo_path = fdem::test::source_path(geo);
    REQUIRE(fs::is_regular_file(geo_path));
    // The name io::mesh_geo gives this .geo at this size today: a different hash means
    // the .geo changed and the committed mesh is stale (run tools/gpu-suite --refresh-meshes).
    char hash[17];
    std::snprintf(hash, sizeof hash, "%016llx",
                  static_cast<unsigned long long>(fdem::fnv1a(read_text(geo_path) + size_text + suffix)));
    CHECK(name == geo_path.stem().string() + "-" + hash + ".msh");
  }
  CHECK(entries > 0);
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name == "MANIFEST") continue;
    CAPTURE(name);
    CHECK(listed.count(name) == 1);
  }
}

}  // TEST_SUITE
