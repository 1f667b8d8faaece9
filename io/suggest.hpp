// "Did you mean ...?" for unknown names in case files and meshes: the one edit distance
// of the tree and the nearest-name rule built on it.
#pragma once
#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>
#include <vector>

namespace fdem::io {

// Case files compare letters ignoring case ("Young" is one step from nothing, not five
// from "young"); mesh physical names are compared as written.
enum class LetterCase { Sensitive, Ignored };

// Levenshtein distance: the fewest single-character insertions, deletions and
// substitutions that turn a into b.
inline std::size_t edit_distance(std::string_view a, std::string_view b,
                                 LetterCase letters = LetterCase::Sensitive) {
  auto same = [letters](char x, char y) {
    if (letters == LetterCase::Sensitive) return x == y;
    return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
  };
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({above + 1, row[j - 1] + 1, diagonal + (same(a[i - 1], b[j - 1]) ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The candidate nearest to `name` (the first of equally near ones), or "" when none is
// within max(2, length/3) edits, too far to be a likely typo. `Names` is any range of
// strings or string views.
template <class Names>
std::string nearest_name(std::string_view name, const Names& candidates,
                         LetterCase letters = LetterCase::Sensitive) {
  std::string_view best;
  std::size_t best_distance = std::string::npos;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(name, c, letters);
    if (d < best_distance) best_distance = d, best = c;
  }
  const std::size_t limit = std::max<std::size_t>(2, name.size() / 3);
  return best_distance <= limit ? std::string(best) : std::string();
}

// " (did you mean 'x'?)" or "".
inline std::string did_you_mean(const std::string& name, const std::vector<std::string>& candidates) {
  const std::string best = nearest_name(name, candidates);
  return best.empty() ? std::string() : " (did you mean '" + best + "'?)";
}

}  // namespace fdem::io
