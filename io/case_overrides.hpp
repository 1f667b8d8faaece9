// --set KEY=VALUE: edits of the parsed case tree before it is read. Each name on the
// path is checked against the schema (a typo gets the suggestion an unknown key in the
// file gets); the value is TOML, or a bare word taken as a string; arrays of tables are
// indexed ("material.0.young=2e9"). Nodes it adds are recorded in `ctx`, so that
// messages about them say "(from --set ...)" instead of a line.
#pragma once
#include <string>

#include <toml++/toml.h>

#include "io/case_toml.hpp"

namespace fdem::io::detail {

void apply_override(toml::table& root, const std::string& text, Context& ctx);

}  // namespace fdem::io::detail
