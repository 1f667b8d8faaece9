// [contact] and its [[contact.pair]] entries.
#include "io/case_tables.hpp"

namespace fdem::io::detail {
namespace {

ContactDampingConfig read_contact_damping(const TableReader& r) {
  r.check_keys(kContactDampingKeys);
  ContactDampingConfig d;
  if (auto t = r.number("transition", kPositive)) d.transition = *t;
  d.exponent = r.number("exponent", Range{1.0, std::numeric_limits<double>::infinity()})
                   .value_or(1.0);
  return d;
}

// `damping = { ... }` inside [contact] or a [[contact.pair]]; nullopt when absent.
std::optional<ContactDampingConfig> read_contact_damping_in(const TableReader& r) {
  const toml::table* t = subtable(r, "damping");
  if (!t) return std::nullopt;
  return read_contact_damping(subtable_reader(r, *t, "damping"));
}

ContactPairConfig read_contact_pair(const TableReader& r,
                                    const std::vector<MaterialConfig>& materials) {
  r.check_keys(kContactPairKeys);
  ContactPairConfig p;
  p.materials = material_names(r, materials);
  p.normal_penalty = r.number("normal_penalty", kPositive);
  p.tangential_penalty = r.number("tangential_penalty", kNonNegative);
  p.friction = r.number("friction", kNonNegative);
  p.damping = read_contact_damping_in(r);
  return p;
}

}  // namespace

ContactConfig read_contact(const TableReader& r, const std::vector<MaterialConfig>& materials) {
  r.check_keys(kContactKeys);
  ContactConfig c;
  // [[contact.pair]] entries alone make an implicit [contact], at their first line.
  if (!r.has("normal_penalty") && r.has("pair"))
    r.ctx().fail(r.table(), r.title() + " is missing required key 'normal_penalty', which "
                                        "[[contact.pair]] entries need (they override "
                                        "[contact]'s values)");
  c.normal_penalty = r.required_number("normal_penalty", kPositive);
  c.tangential_penalty = r.number("tangential_penalty", kNonNegative);  // nullopt: 6 P_n / h (engine/model/model.cpp)
  c.friction = r.number("friction", kNonNegative).value_or(0.0);
  c.damping = read_contact_damping_in(r);
  c.activation = r.choice<std::string>("activation", {{"all", "all"}, {"fractured", "fractured"}})
                     .value_or("all");
  if (r.has("regions") && c.activation != "fractured")
    r.fail("regions", r.key_path("regions") + " is only allowed with " +
                          r.key_path("activation") + " = \"fractured\" (with \"all\" every "
                          "triangle takes part in contact from the start)");
  if (r.has("regions")) c.regions = *r.strings("regions");
  for (const std::string& region : c.regions) check_region_name(r, "regions", region);
  // Default "skin": a user who writes neither key gets the fast path, with a margin the
  // model takes from the mesh (engine/model/model.cpp) unless `skin` gives it.
  c.rebuild = r.choice<ContactRebuild>("rebuild", {{"step", ContactRebuild::Step},
                                                   {"skin", ContactRebuild::Skin}})
                  .value_or(ContactRebuild::Skin);
  const auto skin = r.number_or_keyword("skin", "auto", c.rebuild == ContactRebuild::Skin ? kPositive : kNonNegative);
  if (skin && !*skin && c.rebuild != ContactRebuild::Skin)
    r.fail("skin", r.key_path("skin") + " = \"auto\" needs " + r.key_path("rebuild") +
                       " = \"skin\" (with \"step\" there is no skin to adapt)");
  if (skin && *skin) c.skin = **skin;
  c.skin_auto = c.rebuild == ContactRebuild::Skin && !(skin && *skin);
  if (r.has("joins"))
    r.fail("joins", r.key_path("joins") + " is gone (since 2026-12-03): with activation = \"fractured\" and a "
                    "skin, every detection lists the couples of all triangles and a couple acts from the step "
                    "its second triangle joins, so a join needs neither an extension nor a detection; delete the key");

  PairEntries seen;
  c.pairs = read_entries(r, "pair", "", [&](const TableReader& entry) {
    ContactPairConfig p = read_contact_pair(entry, materials);
    check_new_pair(seen, entry, p.materials);
    return p;
  });
  return c;
}

}  // namespace fdem::io::detail
