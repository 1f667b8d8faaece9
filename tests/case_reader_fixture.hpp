// Shared by the case reader's tests (tests/test_case_*.cpp): a case folder, the
// smallest valid case and the pieces tests append to it, with their line numbers.
#pragma once
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "base/errors.hpp"
#include "io/case_config.hpp"

namespace fdem::test::case_reader {

// A fresh directory per test, holding the case and the mesh files it names.
class CaseDir {
 public:
  CaseDir() {
    static std::mt19937_64 random{std::random_device{}()};
    dir_ = std::filesystem::temp_directory_path() / ("fdem_case_test_" + std::to_string(random()));
    std::filesystem::create_directories(dir_ / "meshes");
    write("m.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    write("meshes/column.geo", "// stands in for a real .geo\n");
  }
  ~CaseDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  CaseDir(const CaseDir&) = delete;
  CaseDir& operator=(const CaseDir&) = delete;

  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

 private:
  std::filesystem::path dir_;
};

// The smallest valid case; tests edit it, so its line numbers matter:
// [mesh] on line 2, [[material]] on line 7, density on line 10, poisson on line 12.
inline const std::string kBase =
    "title = \"t\"\n"        // 1
    "[mesh]\n"               // 2
    "file = \"m.msh\"\n"     // 3
    "[time]\n"               // 4
    "dt = 1.0\n"             // 5
    "end = 10.0\n"           // 6
    "[[material]]\n"         // 7
    "name = \"rock\"\n"      // 8
    "regions = [\"rock\"]\n" // 9
    "density = 2000.0\n"     // 10
    "young = 1e9\n"          // 11
    "poisson = 0.25\n";      // 12

inline std::string with(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  REQUIRE_MESSAGE(at != std::string::npos, "test bug: '" << from << "' not in the case");
  return text.replace(at, from.size(), to);
}

// doctest::Contains takes doctest::String, which has no constructor from std::string.
inline doctest::Contains contains(const std::string& piece) { return doctest::Contains(piece.c_str()); }

// Reads a case from a fresh directory; returns the InputError's message, "" if none.
// (Any other exception escapes and fails the test.) Compared with doctest::Contains.
inline doctest::String error_of(const std::string& text) {
  CaseDir d;
  try {
    fdem::io::read_case(d.write("c.toml", text));
  } catch (const fdem::InputError& e) {
    return e.what();
  }
  return "";
}

inline const std::string kSecondMaterial =
    "[[material]]\n"
    "name = \"slate\"\n"
    "regions = [\"slate\"]\n"
    "density = 2700.0\n"
    "young = 5e10\n"
    "poisson = 0.3\n";

// The keys of a [material.fracture] without its header: 6 lines.
inline const std::string kFractureKeys =
    "tensile_strength = 1.77e6\n"
    "cohesion = 5.0e6\n"
    "friction_angle = 25.0\n"
    "gf1 = 16.0\n"
    "gf2 = 160.0\n"
    "penalty = { opening = 12200e9, sliding = 12200e9, overlap = 12200e9 }\n";

// kBase + this: [material.fracture] of "rock" on line 13, tensile_strength on 14, gf1 on
// 17, penalty on 19, so what a test appends starts on line 20 (inside the table).
inline const std::string kFracture = "[material.fracture]\n" + kFractureKeys;

// Two fracturable materials ("rock" and "slate") and one [[interface]] between them:
// [[interface]] on line 33, materials on line 34, so what a test appends starts on line 41.
inline const std::string kTwoFracturable = kBase + kFracture + kSecondMaterial + kFracture;
inline const std::string kInterface = kTwoFracturable + "[[interface]]\n"
                                                 "materials = [\"rock\", \"slate\"]\n" +
                               kFractureKeys;

// Two materials and the smallest [contact]: [contact] on line 19, normal_penalty on line
// 20, so what a test appends starts on line 21.
inline const std::string kContact = kBase + kSecondMaterial +
                             "[contact]\n"
                             "normal_penalty = 1e9\n";

}  // namespace fdem::test::case_reader
