// Case reader: [mesh], [time], [output], [gravity], [damping] (io/case_setup_tables.cpp).
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "case_reader_fixture.hpp"

namespace {

namespace fs = std::filesystem;
using fdem::InputError;
using fdem::io::CaseConfig;
using fdem::io::read_case;
using namespace fdem::test::case_reader;

}  // namespace

TEST_SUITE("case") {

TEST_CASE("mesh: missing file, geo and file together, neither, size without geo") {
  CaseDir d;
  const std::string path = d.write("c.toml", with(kBase, "m.msh", "nope.msh"));
  CHECK_THROWS_WITH_AS(read_case(path),
                       contains(path + ":3: mesh.file: file not found: " +
                                         d.path("nope.msh")),
                       InputError);
  CHECK(error_of(with(kBase, "[time]", "geo = \"meshes/column.geo\"\n[time]")) ==
        contains(":4: mesh.geo and mesh.file are exclusive"));
  CHECK(error_of(with(kBase, "file = \"m.msh\"\n", "")) ==
        contains(":2: [mesh] needs one of 'geo' or 'file'"));
  CHECK(error_of(with(kBase, "[time]", "size = 0.5\n[time]")) ==
        contains(":4: mesh.size only applies with mesh.geo"));
  CHECK(error_of(with(kBase, "title = \"t\"\n[mesh]\nfile = \"m.msh\"\n", "")) ==
        contains("missing required table [mesh]"));
}

}  // TEST_SUITE("case")
