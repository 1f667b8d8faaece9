// The validation driver's vocabulary: an entry runs one or more cases at full size and
// measures figures from their output; each figure has an expected value or range and
// names the case README section and the seed paper's number it checks. The table of
// entries is validation/runs.cpp; validation/main.cpp runs it.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "engine/run/run.hpp"

namespace fdem::validation {

// How a measured value must compare with what is expected.
struct Expect {
  enum class Kind { Below, Above, Between, Equal, Approx };
  Kind kind = Kind::Below;
  double a = 0, b = 0;

  bool holds(double value) const;
  std::string text() const;  // "< 0.01", "> 0.99", "between 0.8 and 1.6", "= 6400", "≈ 0.408: |diff| < 0.02 (1 + the larger)"
};

Expect below(double limit);                 // value < limit
Expect above(double limit);                 // value > limit
Expect between(double low, double high);    // low < value < high
Expect equal(double expected);              // value == expected
// |value − expected| < epsilon (1 + max(|value|, |expected|)): doctest's
// Approx(expected).epsilon(epsilon), the rule these checks had as doctest tests. For
// figures much larger than 1 it is a relative tolerance of epsilon; for figures of
// order 1 or below it is looser (the sliding distances: 0.02 × (1 m + L)).
Expect approx(double expected, double epsilon);

// One expected figure of an entry.
struct Figure {
  std::string key;        // the name under which the entry's measure() reports it
  std::string what;       // what it is, with its unit
  Expect expect;
  std::string reference;  // what it checks: the case README's section, the seed paper's number
};

// One run of a case file with `--set` overrides; its output goes to OUT/<dir>.
struct Run {
  std::string dir;
  std::string case_file;  // relative to the source tree
  std::vector<std::string> overrides;
};

// The runs of an entry, done: where their output is and what run_case returned.
struct Results {
  std::string out;                              // the validation output folder
  std::map<std::string, RunSummary> summaries;  // by Run::dir
  std::string dir(const std::string& run) const { return out + "/" + run; }
};

// What an entry measured: figure values by key, and notes printed beside them.
struct Measured {
  std::map<std::string, double> values;
  std::vector<std::string> notes;
};

struct Entry {
  std::string name;   // selects the entry on the command line
  std::string title;
  std::vector<Run> runs;
  std::vector<Figure> figures;
  std::function<Measured(const Results&)> measure;
};

// The table: every validation entry, in the order `fdem_validate` runs them.
const std::vector<Entry>& entries();

}  // namespace fdem::validation
