// --set: "a.b.c=value" edits the parsed tree before validation.
#include "io/case_overrides.hpp"

#include <algorithm>

namespace fdem::io::detail {
namespace {

bool is_index(std::string_view s) {
  return !s.empty() && s.size() < 10 &&
         std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

void apply_override(toml::table& root, const std::string& text, Context& ctx) {
  const std::string source_name = "--set " + text;
  auto fail = [&](const std::string& what) -> void {
    throw InputError(ctx.from_set(source_name) + ": " + what);
  };
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos) fail("expected key.path=value");
  const std::string key_path = text.substr(0, eq), value_text = text.substr(eq + 1);
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t dot = key_path.find('.', start);
    parts.push_back(key_path.substr(start, dot - start));
    if (parts.back().empty()) fail("empty component in key path '" + key_path + "'");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }

  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value_text, source_name);
  } catch (const toml::parse_error& e) {
    // A bare word (output.dir=out2) is taken as a string, as a shell user would expect;
    // anything that starts like an array, table or quoted string must be valid TOML.
    const bool bare_word = !value_text.empty() && value_text.find_first_of("[]{}\"'\n=") == std::string::npos;
    if (!bare_word)
      fail("value '" + value_text + "' is not valid TOML (" + std::string(e.description()) + ")");
    try {
      parsed = toml::parse("v = '" + value_text + "'", source_name);  // a TOML literal string
    } catch (const toml::parse_error& literal) {  // e.g. a control character: no TOML string holds it
      fail("value '" + value_text + "' is neither valid TOML nor a plain word (" + std::string(literal.description()) + ")");
    }
  }
  if (parsed.size() != 1 || !parsed.contains("v")) fail("the value must be one TOML value");
  ctx.add_override(source_name);
  toml::node& value = *parsed.get("v");

  // Walk down, checking each name against the schema so a typo is caught here, with the
  // same suggestion an unknown key in the file gets.
  toml::node* cur = &root;
  const Schema* schema = &kRootKeys;
  // The path walked so far as given ("contact.pair.0") and as the reader spells it
  // ("contact.pair[0]"), and the table kind for messages ("[[contact.pair]]").
  std::string shown, path, heading;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    if (toml::array* entries = cur->as_array()) {
      if (!is_index(part))
        fail(shown + " is an array of tables: give an index, e.g. " + shown + ".0." + part);
      std::size_t index = 0;  // is_index: at most 9 digits, so no overflow
      for (char c : part) index = index * 10 + static_cast<std::size_t>(c - '0');
      if (index >= entries->size())
        fail("index " + part + " is out of range: the case has " +
             std::to_string(entries->size()) + " " + heading + " entries (indices start at 0)");
      if (last && !value.is_table()) fail(shown + "." + part + " must be a table");
      if (last) {
        entries->replace(entries->cbegin() + static_cast<std::ptrdiff_t>(index), std::move(value));
        return;
      }
      cur = entries->get(index);
      shown += "." + part;
      path += "[" + part + "]";
      continue;
    }
    toml::table& table = *cur->as_table();
    const Field* field = schema->find(part);
    if (!field) {
      // A name not in the file yet is a table when the path goes on through it.
      const toml::node* existing = table.get(part);
      const Shape found = existing ? shape_of(*existing)
                          : last   ? Shape::Key
                          : is_index(parts[i + 1]) ? Shape::TableArray
                                                   : Shape::Table;
      fail(unknown_name_message(part, found, *schema, heading));
    }
    if (last) {
      table.insert_or_assign(part, std::move(value));
      return;
    }
    shown += (shown.empty() ? "" : ".") + part;
    path += (path.empty() ? "" : ".") + part;
    toml::node* child = table.get(part);
    if (field->shape == Shape::Key) fail(shown + " is a value, not a table");
    if (field->shape == Shape::TableArray) {
      heading = "[[" + path + "]]";
      const std::size_t count = child && child->is_array() ? child->as_array()->size() : 0;
      if (!child || !child->is_array_of_tables()) {
        if (is_index(parts[i + 1]))
          fail("index " + parts[i + 1] + " is out of range: the case has " +
               std::to_string(count) + " " + heading + " entries");
        fail(shown + " is an array of tables: give an index, e.g. " + shown + ".0");
      }
    } else {
      heading = i == 0 ? "[" + part + "]" : path;
      if (!child) {
        child = &table.insert(part, toml::table{}).first->second;
        ctx.note_created(child, source_name);
      } else if (!child->is_table()) {
        fail(shown + " is not a table (found " + describe(*child) + ")");
      }
    }
    cur = child;
    schema = field->child;
  }
}

}  // namespace fdem::io::detail
