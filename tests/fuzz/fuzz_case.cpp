// Fuzz target: the case file and its --set overrides, as `fdem check CASE` reads them
// (engine/run/run.cpp prepare_case: io::read_case, then the mesh, the model, the stable step
// and the probes). The input is the case text; each line that starts with "#--set " also
// gives an override (the rest of the line), so the TOML parser sees it as a comment.
// Mesh files named by the case resolve against the scratch directory, which holds the
// small committed meshes of tests/data/cases (the seeds name them, tests/fuzz/make_corpus.sh).
// A case whose mesh is a .geo stops after read_case: meshing is fuzz_geo's part, and
// prepare_case would create the output directory the input names.
#include <filesystem>
#include <string>
#include <vector>

#include "engine/run/run.hpp"
#include "fuzz_common.hpp"
#include "io/case_config.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  namespace fs = std::filesystem;
  fdem::fuzz::no_programs();
  for (const char* mesh : {"column_small.msh", "blast_small.msh"})
    fs::copy_file(fs::path(FDEM_SOURCE_DIR) / "tests/data/cases" / mesh, fs::path(fdem::fuzz::scratch_dir()) / mesh,
                  fs::copy_options::overwrite_existing);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  static const std::string marker = "#--set ";
  for (size_t at = 0; at < text.size();) {
    size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    if (text.compare(at, marker.size(), marker) == 0) overrides.push_back(text.substr(at + marker.size(), end - at - marker.size()));
    at = end + 1;
  }
  const std::string path = fdem::fuzz::write_input("case.toml", data, size);
  try {
    const fdem::io::CaseConfig c = fdem::io::read_case(path, overrides);
    if (!c.mesh.file.empty()) fdem::prepare_case(path, overrides);
  } catch (const fdem::InputError&) {
    // The refusal fdem reports with exit 2: what bad input must get.
  }
  return 0;
}
