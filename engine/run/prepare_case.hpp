// Reading a case (with --set overrides), meshing a .geo if needed, building the model and
// resolving Δt and the step count; the output folder's checks.
#pragma once
#include <string>
#include <vector>

#include "engine/model/prepared_case.hpp"

namespace fdem {

// Throws InputError for anything wrong, including a Δt above the stable estimate (unless
// mass scaling makes any Δt stable), an output.checkpoint_every shorter than Δt, and an
// output.dir that is the root of the file system or a system directory (/etc, /usr, ...).
PreparedCase prepare_case(const std::string& case_path, const std::vector<std::string>& overrides);

// Throws OutputError, with the message run_case would give, when the output folder can
// neither be written nor made, or one of the run's file names is taken by something other
// than a file. run_case checks it before anything is computed; `fdem check` too.
void check_output(const PreparedCase& prepared);
// Makes the output folder (OutputError when it cannot).
void make_output_dir(const std::string& dir);

}  // namespace fdem
