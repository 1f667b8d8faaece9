// fdem_validate: runs the validation table (validation/runs.cpp), the cases at full
// size, and checks every figure against its expected value.
//
//   fdem_validate [--out DIR] [--list] [--set KEY=VALUE]... [NAME...]
//
// Each run writes to DIR/<run>/ (default: the build tree's validate/, never the source
// tree); the table of figures goes to stdout and to DIR/summary.md. Exit code 0 when
// every figure is as expected, 1 when one is not or a run failed, 2 for a bad command
// line. The device is FDEM_DEVICE's, else auto (as for the unit tests).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "case_files.hpp"
#include "fixture.hpp"
#include "validation.hpp"

using namespace fdem;
using namespace fdem::validation;
namespace fs = std::filesystem;

namespace {

const char* kUsage =
    "usage: fdem_validate [--out DIR] [--list] [--set KEY=VALUE]... [NAME...]\n"
    "  Runs the validation entries (all, or those NAMEd) and checks their figures.\n"
    "  --out DIR  where the runs write (DIR/<run>/) and DIR/summary.md; default " FDEM_VALIDATE_DIR "\n"
    "  --list     print the entries, their runs and expected figures, and run nothing\n"
    "  --set KEY=VALUE  a case override added to every run (after the entry's own), e.g. a coarser\n"
    "             mesh.size for a trial on a CPU; the figures' expected values stay the full cases'\n";

struct Row {
  std::string entry;
  const Figure* figure;
  double value;  // NaN when not measured
  bool pass;
};

std::string number(double v) {
  if (std::isnan(v)) return "not measured";
  std::ostringstream out;
  out.precision(6);
  out << v;
  return out.str();
}

// A markdown table cell: pipes in the text would end it.
std::string cell(const std::string& text) {
  std::string s;
  for (char c : text) s += c == '|' ? std::string("\\|") : std::string(1, c);
  return s;
}

std::string joined(const std::vector<std::string>& words) {
  std::string s;
  for (const auto& w : words) s += (s.empty() ? "" : " ") + std::string("--set ") + w;
  return s;
}

void list(const std::vector<Entry>& table) {
  for (const Entry& e : table) {
    std::cout << e.name << ": " << e.title << "\n";
    for (const Run& r : e.runs) std::cout << "  run " << r.dir << ": " << r.case_file << " " << joined(r.overrides) << "\n";
    for (const Figure& f : e.figures)
      std::cout << "  figure " << f.what << ": " << f.expect.text() << "  [" << f.reference << "]\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = FDEM_VALIDATE_DIR;
  bool only_list = false;
  std::vector<std::string> names, extra;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--out" && k + 1 < argc) {
      out = argv[++k];
    } else if (a == "--set" && k + 1 < argc) {
      extra.push_back(argv[++k]);
    } else if (a == "--list") {
      only_list = true;
    } else if (a == "-h" || a == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::cerr << "fdem_validate: unknown option '" << a << "'\n" << kUsage;
      return 2;
    } else {
      names.push_back(a);
    }
  }
  const auto& table = entries();
  std::vector<const Entry*> chosen;
  for (const Entry& e : table)
    if (names.empty() || std::find(names.begin(), names.end(), e.name) != names.end()) chosen.push_back(&e);
  for (const auto& n : names)
    if (std::none_of(table.begin(), table.end(), [&](const Entry& e) { return e.name == n; })) {
      std::cerr << "fdem_validate: no entry '" << n << "'; the entries:";
      for (const Entry& e : table) std::cerr << " " << e.name;
      std::cerr << "\n";
      return 2;
    }
  if (only_list) {
    list(table);
    return 0;
  }

  std::vector<Row> rows;
  std::vector<std::string> failed_runs;
  try {
    out = fs::absolute(out).lexically_normal().string();
    fs::create_directories(out);
    const std::string device = test::context().description();
    std::cout << "device: " << device << "\noutput: " << out << "\n";
  } catch (const std::exception& e) {
    std::cerr << "fdem_validate: " << e.what() << "\n";
    return 1;
  }
  for (const Entry* entry : chosen) {
    std::cout << "\n== " << entry->name << ": " << entry->title << std::endl;
    const auto start = std::chrono::steady_clock::now();
    Results results{out, {}};
    std::string error;
    for (const Run& r : entry->runs) {
      const std::string dir = results.dir(r.dir);
      std::vector<std::string> overrides = r.overrides;
      overrides.insert(overrides.end(), extra.begin(), extra.end());
      overrides.push_back("output.dir=\"" + dir + "\"");
      std::cout << "-- " << r.dir << ": " << r.case_file << " " << joined(overrides) << std::endl;
      try {
        fs::remove_all(dir);  // nothing of an earlier run is read back
        const PreparedCase p = prepare_case(test::source_path(r.case_file), overrides);
        results.summaries[r.dir] = test::run(p, {}, &std::cout);
      } catch (const std::exception& e) {
        error = r.dir + ": " + e.what();
        break;
      }
    }
    Measured measured;
    if (error.empty()) {
      try {
        measured = entry->measure(results);
      } catch (const std::exception& e) {
        error = "measuring: " + std::string(e.what());
      }
    }
    if (!error.empty()) {
      std::cout << "FAILED " << error << "\n";
      failed_runs.push_back(entry->name + ": " + error);
    }
    for (const auto& note : measured.notes) std::cout << "   " << note << "\n";
    for (const Figure& f : entry->figures) {
      const auto it = measured.values.find(f.key);
      const double value = it == measured.values.end() ? std::nan("") : it->second;
      const bool pass = !std::isnan(value) && f.expect.holds(value);
      rows.push_back({entry->name, &f, value, pass});
      std::cout << (pass ? "   ok    " : "   MISS  ") << f.what << ": " << number(value) << " (expected " << f.expect.text()
                << ")\n";
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "   " << entry->name << " took " << number(seconds) << " s" << std::endl;
  }

  std::ostringstream summary;
  summary << "| entry | figure | measured | expected | checks | result |\n|---|---|---|---|---|---|\n";
  size_t missed = 0;
  for (const Row& r : rows) {
    missed += !r.pass;
    summary << "| " << r.entry << " | " << cell(r.figure->what) << " | " << number(r.value) << " | "
            << cell(r.figure->expect.text()) << " | " << cell(r.figure->reference) << " | " << (r.pass ? "ok" : "MISS") << " |\n";
  }
  for (const auto& f : failed_runs) summary << "\nfailed: " << f << "\n";
  std::ofstream(out + "/summary.md") << summary.str();
  std::cout << "\n" << summary.str() << "\n"
            << rows.size() - missed << " of " << rows.size() << " figures as expected"
            << (failed_runs.empty() ? "" : ", " + std::to_string(failed_runs.size()) + " entries failed to run")
            << "; the table is in " << out << "/summary.md\n";
  return missed == 0 && failed_runs.empty() ? 0 : 1;
}
