// Exodus and history output: files written by the writers are read back with the plain
// netCDF-C API, so the checks do not depend on the writers' own code.
#include <doctest/doctest.h>
#include <netcdf.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "io/exodus_writer.hpp"
#include "io/history_writer.hpp"

namespace fs = std::filesystem;
using fdem::io::ExodusBlock;
using fdem::io::ExodusWriter;
using fdem::io::HistoryVariable;
using fdem::io::HistoryWriter;

namespace {

// A fresh directory under /tmp, removed at the end of the test.
struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/fdem_exodus_test_XXXXXX";
    const char* made = mkdtemp(tmpl);
    REQUIRE(made != nullptr);
    path = made;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

// Where the reference files go: FDEM_TOOLS_TEST_DIR when set, so that
// tests/test_tools.sh can plot them, else the test's temporary directory.
std::string reference_dir(const TempDir& tmp) {
  const char* dir = std::getenv("FDEM_TOOLS_TEST_DIR");
  if (dir == nullptr || *dir == '\0') return tmp.path.string();
  fs::create_directories(dir);
  return dir;
}

// Read-only handle on a netCDF file, closed on scope exit.
struct NcReader {
  int id = -1;
  explicit NcReader(const std::string& path) {
    const int status = nc_open(path.c_str(), NC_NOWRITE, &id);
    INFO("nc_open(" << path << "): " << nc_strerror(status));
    REQUIRE(status == NC_NOERR);
  }
  ~NcReader() {
    if (id >= 0) nc_close(id);
  }
  int format() const {
    int f = -1;
    REQUIRE(nc_inq_format(id, &f) == NC_NOERR);
    return f;
  }
  bool has_dim(const std::string& name) const {
    int dimid = -1;
    return nc_inq_dimid(id, name.c_str(), &dimid) == NC_NOERR;
  }
  bool has_var(const std::string& name) const {
    int varid = -1;
    return nc_inq_varid(id, name.c_str(), &varid) == NC_NOERR;
  }
  size_t dim_len(const std::string& name) const {
    int dimid = -1;
    INFO("dimension " << name);
    REQUIRE(nc_inq_dimid(id, name.c_str(), &dimid) == NC_NOERR);
    size_t len = 0;
    REQUIRE(nc_inq_dimlen(id, dimid, &len) == NC_NOERR);
    return len;
  }
  int var(const std::string& name) const {
    int varid = -1;
    INFO("variable " << name);
    REQUIRE(nc_inq_varid(id, name.c_str(), &varid) == NC_NOERR);
    return varid;
  }
  // varid NC_GLOBAL for global attributes.
  nc_type att_type(int varid, const std::string& name) const {
    nc_type type = NC_NAT;
    size_t len = 0;
    INFO("attribute " << name);
    REQUIRE(nc_inq_att(id, varid, name.c_str(), &type, &len) == NC_NOERR);
    REQUIRE(len >= 1);
    return type;
  }
  std::string att_text(int varid, const std::string& name) const {
    REQUIRE(att_type(varid, name) == NC_CHAR);
    size_t len = 0;
    REQUIRE(nc_inq_attlen(id, varid, name.c_str(), &len) == NC_NOERR);
    std::string value(len, '\0');
    REQUIRE(nc_get_att_text(id, varid, name.c_str(), value.data()) == NC_NOERR);
    return value;
  }
  int att_int(int varid, const std::string& name) const {
    REQUIRE(att_type(varid, name) == NC_INT);
    int value = 0;
    REQUIRE(nc_get_att_int(id, varid, name.c_str(), &value) == NC_NOERR);
    return value;
  }
  float att_float(int varid, const std::string& name) const {
    REQUIRE(att_type(varid, name) == NC_FLOAT);
    float value = 0;
    REQUIRE(nc_get_att_float(id, varid, name.c_str(), &value) == NC_NOERR);
    return value;
  }
  std::vector<int> ints(const std::string& name, size_t count) const {
    std::vector<int> v(count);
    REQUIRE(nc_get_var_int(id, var(name), v.data()) == NC_NOERR);
    return v;
  }
  std::vector<double> doubles(const std::string& name, size_t count) const {
    std::vector<double> v(count);
    REQUIRE(nc_get_var_double(id, var(name), v.data()) == NC_NOERR);
    return v;
  }
  // One record of a (time, n) variable.
  std::vector<double> frame(const std::string& name, size_t rec, size_t n) const {
    std::vector<double> v(n);
    const size_t start[2] = {rec, 0};
    const size_t count[2] = {1, n};
    REQUIRE(nc_get_vara_double(id, var(name), start, count, v.data()) == NC_NOERR);
    return v;
  }
  // Rows of a (count, len_name) char variable, raw (padding included).
  std::vector<std::string> raw_rows(const std::string& name, size_t rows,
                                    size_t width) const {
    std::vector<char> buf(rows * width);
    REQUIRE(nc_get_var_text(id, var(name), buf.data()) == NC_NOERR);
    std::vector<std::string> out;
    for (size_t r = 0; r < rows; ++r) out.emplace_back(buf.data() + r * width, width);
    return out;
  }
};

// Checks that a raw char row holds `name` followed by NULs only.
void check_padded(const std::string& row, const std::string& name) {
  INFO("row for '" << name << "'");
  CHECK(row.substr(0, name.size()) == name);
  CHECK(row.find_first_not_of('\0', name.size()) == std::string::npos);
}

// The reference mesh: a unit square cut along its diagonal 0-2 into two TRI3 (block
// "granite", nodes 0 1 2 and 0 2 3) and the TRI3 1 4 2 to its right (block "steel"),
// with node 4 at (2, 0.5).
const std::vector<double> kX = {0.0, 1.0, 1.0, 0.0, 2.0};
const std::vector<double> kY = {0.0, 0.0, 1.0, 1.0, 0.5};
const std::vector<ExodusBlock> kBlocks = {
    {"granite", "TRI3", 3, {0, 1, 2, 0, 2, 3}},
    {"steel", "TRI3", 3, {1, 4, 2}},
};
const std::vector<std::string> kNodalNames = {"DISPLX", "DISPLY"};
const std::vector<std::string> kElemNames = {"SXX", "SYY", "SXY"};
const std::vector<double> kTimes = {0.0, 1.5e-3, 3.0e-3};

double nodal_value(size_t var, size_t frame, size_t node) {
  // A stretch in x and a squeeze in y that grow with time: visible when plotted.
  const double s = 0.05 * static_cast<double>(frame);
  return var == 0 ? s * kX[node] : -0.5 * s * kY[node];
}

double elem_value(size_t var, size_t frame, size_t block, size_t elem) {
  return -1.0e6 * static_cast<double>((frame + 1) * (elem + 1 + 3 * block)) -
         2.5e5 * static_cast<double>(var);
}

std::vector<std::vector<double>> nodal_frame(size_t frame) {
  std::vector<std::vector<double>> nodal(kNodalNames.size(), std::vector<double>(kX.size()));
  for (size_t k = 0; k < nodal.size(); ++k)
    for (size_t n = 0; n < kX.size(); ++n) nodal[k][n] = nodal_value(k, frame, n);
  return nodal;
}

std::vector<std::vector<std::vector<double>>> elem_frame(size_t frame) {
  std::vector<std::vector<std::vector<double>>> elem(kElemNames.size());
  for (size_t k = 0; k < elem.size(); ++k)
    for (size_t b = 0; b < kBlocks.size(); ++b) {
      const size_t n = kBlocks[b].connectivity.size() / 3;
      std::vector<double> values(n);
      for (size_t e = 0; e < n; ++e) values[e] = elem_value(k, frame, b, e);
      elem[k].push_back(values);
    }
  return elem;
}

void write_reference_exodus(const std::string& path, size_t frames, const fdem::io::ExodusOptions& options = {}) {
  ExodusWriter w(path, "fdem-cl test mesh", kX, kY, kBlocks, kNodalNames, kElemNames, options);
  for (size_t f = 0; f < frames; ++f) w.write_frame(kTimes[f], nodal_frame(f), elem_frame(f));
  CHECK(w.frames_written() == static_cast<int>(frames));
  w.close();
}

// Checks the first `frames` frames of a reference file: times and every value (each as
// `stored` turns it, e.g. rounded to float).
void check_reference_frames(const NcReader& nc, size_t frames, double (*stored)(double) = [](double v) { return v; }) {
  REQUIRE(nc.dim_len("time_step") == frames);
  CHECK(nc.doubles("time_whole", frames) == std::vector<double>(kTimes.begin(),
                                                                kTimes.begin() + frames));
  for (size_t f = 0; f < frames; ++f) {
    for (size_t k = 0; k < kNodalNames.size(); ++k) {
      const auto v = nc.frame("vals_nod_var" + std::to_string(k + 1), f, kX.size());
      for (size_t n = 0; n < kX.size(); ++n) CHECK(v[n] == stored(nodal_value(k, f, n)));
    }
    for (size_t k = 0; k < kElemNames.size(); ++k)
      for (size_t b = 0; b < kBlocks.size(); ++b) {
        const size_t n = kBlocks[b].connectivity.size() / 3;
        const auto v = nc.frame(
            "vals_elem_var" + std::to_string(k + 1) + "eb" + std::to_string(b + 1), f, n);
        for (size_t e = 0; e < n; ++e) CHECK(v[e] == stored(elem_value(k, f, b, e)));
      }
  }
}

const std::vector<HistoryVariable> kHistoryVars = {
    {"kinetic_energy", "J", "kinetic energy of all elements"},
    {"top_force_y", "N", "vertical force on the top platen"},
    {"bottom_force_y", "N", "vertical force on the bottom platen"},
};

double history_value(size_t var, size_t row) {
  const double t = static_cast<double>(row);
  return var == 0 ? 1.0e-3 * (1.0 + t * t) : (var == 1 ? -2.0e4 * t : 1.9e4 * t);
}

void write_reference_history(const std::string& path, size_t rows) {
  HistoryWriter h(path, "fdem-cl test history", kHistoryVars);
  for (size_t r = 0; r < rows; ++r) {
    std::vector<double> values;
    for (size_t k = 0; k < kHistoryVars.size(); ++k) values.push_back(history_value(k, r));
    h.append(1.0e-4 * static_cast<double>(r), values);
  }
  CHECK(h.rows_written() == static_cast<int>(rows));
  h.close();
}

// Runs `body` in a forked child that the child then kills with SIGKILL, so nothing
// closes or flushes the file the normal way. Returns once the child is gone.
template <class Body>
void run_then_sigkill(Body body) {
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    try {
      body();
    } catch (...) {
      _exit(3);
    }
    kill(getpid(), SIGKILL);
    _exit(4);  // not reached
  }
  int wstatus = 0;
  REQUIRE(waitpid(pid, &wstatus, 0) == pid);
  INFO("child wait status " << wstatus);
  REQUIRE(WIFSIGNALED(wstatus));
  CHECK(WTERMSIG(wstatus) == SIGKILL);
}

template <class F>
std::string output_error_message(F f) {
  try {
    f();
  } catch (const fdem::OutputError& e) {
    return e.what();
  }
  FAIL("no fdem::OutputError thrown");
  return {};
}

}  // namespace

TEST_SUITE("exodus") {
  TEST_CASE("exodus file has the header, blocks and frames readers need") {
    TempDir tmp;
    const std::string path = reference_dir(tmp) + "/tiny.exo";
    write_reference_exodus(path, 3);

    NcReader nc(path);
    // Classic 64-bit offset, not netCDF-4: what keeps a killed run's frames readable.
    CHECK(nc.format() == NC_FORMAT_64BIT_OFFSET);

    CHECK(nc.att_float(NC_GLOBAL, "api_version") >= 2.0f);
    CHECK(nc.att_float(NC_GLOBAL, "version") >= 2.0f);
    CHECK(nc.att_int(NC_GLOBAL, "floating_point_word_size") == 8);
    CHECK(nc.att_int(NC_GLOBAL, "file_size") == 1);
    CHECK(nc.att_int(NC_GLOBAL, "maximum_name_length") == 32);
    CHECK(nc.att_int(NC_GLOBAL, "int64_status") == 0);
    CHECK(nc.att_text(NC_GLOBAL, "title") == "fdem-cl test mesh");

    CHECK(nc.dim_len("len_string") == 33);
    CHECK(nc.dim_len("len_line") == 81);
    CHECK(nc.dim_len("four") == 4);
    CHECK(nc.dim_len("len_name") == 33);
    CHECK(nc.dim_len("num_dim") == 2);
    CHECK(nc.dim_len("num_nodes") == 5);
    CHECK(nc.dim_len("num_elem") == 3);
    CHECK(nc.dim_len("num_el_blk") == 2);
    CHECK(nc.dim_len("num_el_in_blk1") == 2);
    CHECK(nc.dim_len("num_el_in_blk2") == 1);
    CHECK(nc.dim_len("num_nod_per_el1") == 3);
    CHECK(nc.dim_len("num_nod_per_el2") == 3);
    CHECK(nc.dim_len("num_nod_var") == 2);
    CHECK(nc.dim_len("num_elem_var") == 3);
    int unlimited = -1;
    REQUIRE(nc_inq_unlimdim(nc.id, &unlimited) == NC_NOERR);
    int time_dim = -1;
    REQUIRE(nc_inq_dimid(nc.id, "time_step", &time_dim) == NC_NOERR);
    CHECK(unlimited == time_dim);

    CHECK(nc.doubles("coordx", 5) == kX);
    CHECK(nc.doubles("coordy", 5) == kY);
    const auto coor_names = nc.raw_rows("coor_names", 2, 33);
    check_padded(coor_names[0], "x");
    check_padded(coor_names[1], "y");

    CHECK(nc.ints("eb_status", 2) == std::vector<int>{1, 1});
    CHECK(nc.ints("eb_prop1", 2) == std::vector<int>{1, 2});
    CHECK(nc.att_text(nc.var("eb_prop1"), "name") == "ID");
    const auto eb_names = nc.raw_rows("eb_names", 2, 33);
    check_padded(eb_names[0], "granite");
    check_padded(eb_names[1], "steel");

    CHECK(nc.ints("connect1", 6) == std::vector<int>{1, 2, 3, 1, 3, 4});
    CHECK(nc.ints("connect2", 3) == std::vector<int>{2, 5, 3});
    CHECK(nc.att_text(nc.var("connect1"), "elem_type") == "TRI3");
    CHECK(nc.att_text(nc.var("connect2"), "elem_type") == "TRI3");

    const auto nod_names = nc.raw_rows("name_nod_var", 2, 33);
    check_padded(nod_names[0], "DISPLX");
    check_padded(nod_names[1], "DISPLY");
    const auto elem_names = nc.raw_rows("name_elem_var", 3, 33);
    check_padded(elem_names[0], "SXX");
    check_padded(elem_names[1], "SYY");
    check_padded(elem_names[2], "SXY");
    CHECK(nc.ints("elem_var_tab", 6) == std::vector<int>(6, 1));

    check_reference_frames(nc, 3);
  }

  TEST_CASE("precision float: frame values read back equal (float)value; coordinates and times stay double") {
    TempDir tmp;
    const std::string path = tmp.file("float.exo");
    write_reference_exodus(path, 3, {true, false});
    NcReader nc(path);
    CHECK(nc.format() == NC_FORMAT_64BIT_OFFSET);  // still the crash-safe classic file
    auto type = [&](const std::string& name) {
      nc_type t = NC_NAT;
      REQUIRE(nc_inq_vartype(nc.id, nc.var(name), &t) == NC_NOERR);
      return t;
    };
    CHECK(type("vals_nod_var1") == NC_FLOAT);
    CHECK(type("vals_elem_var3eb2") == NC_FLOAT);
    CHECK(type("coordx") == NC_DOUBLE);
    CHECK(type("coordy") == NC_DOUBLE);
    CHECK(type("time_whole") == NC_DOUBLE);
    CHECK(nc.doubles("coordx", 5) == kX);
    // Some reference values (0.05 × frame × x) are not floats: the check sees the rounding.
    CHECK(static_cast<double>(static_cast<float>(nodal_value(0, 1, 1))) != nodal_value(0, 1, 1));
    check_reference_frames(nc, 3, [](double v) { return static_cast<double>(static_cast<float>(v)); });
  }

  TEST_CASE("compress: a netCDF-4 file with deflated frame variables, every value identical") {
    TempDir tmp;
    for (const bool float_values : {false, true}) {
      CAPTURE(float_values);
      const std::string path = tmp.file(float_values ? "cf.exo" : "c.exo");
      write_reference_exodus(path, 3, {float_values, true});
      NcReader nc(path);
      CHECK(nc.format() == NC_FORMAT_NETCDF4);
      int shuffle = 0, deflate = 0, level = 0;
      REQUIRE(nc_inq_var_deflate(nc.id, nc.var("vals_elem_var1eb1"), &shuffle, &deflate, &level) == NC_NOERR);
      CHECK(deflate == 1);
      CHECK(shuffle == 1);
      CHECK(nc.att_int(NC_GLOBAL, "floating_point_word_size") == 8);
      CHECK(nc.ints("connect1", 6) == std::vector<int>{1, 2, 3, 1, 3, 4});
      CHECK(nc.doubles("coordy", 5) == kY);
      if (float_values)
        check_reference_frames(nc, 3, [](double v) { return static_cast<double>(static_cast<float>(v)); });
      else
        check_reference_frames(nc, 3);
    }
  }

  TEST_CASE("exodus file without nodal or element variables leaves their parts out") {
    TempDir tmp;
    const std::string path = tmp.file("bare.exo");
    {
      ExodusWriter w(path, "bare", kX, kY, kBlocks, {}, {});
      w.write_frame(0.25, {}, {});
      w.write_frame(0.5, {}, {});
    }  // the destructor closes
    NcReader nc(path);
    CHECK_FALSE(nc.has_dim("num_nod_var"));
    CHECK_FALSE(nc.has_dim("num_elem_var"));
    CHECK_FALSE(nc.has_var("name_nod_var"));
    CHECK_FALSE(nc.has_var("name_elem_var"));
    CHECK_FALSE(nc.has_var("elem_var_tab"));
    CHECK(nc.dim_len("time_step") == 2);
    CHECK(nc.doubles("time_whole", 2) == std::vector<double>{0.25, 0.5});

    // Only element variables.
    const std::string elem_only = tmp.file("elem_only.exo");
    {
      ExodusWriter w(elem_only, "elem only", kX, kY, kBlocks, {}, kElemNames);
      w.write_frame(0.0, {}, elem_frame(0));
    }
    NcReader nc2(elem_only);
    CHECK_FALSE(nc2.has_dim("num_nod_var"));
    CHECK(nc2.dim_len("num_elem_var") == 3);
    CHECK(nc2.frame("vals_elem_var1eb2", 0, 1)[0] == elem_value(0, 0, 1, 0));
  }

  TEST_CASE("exodus writer rejects inconsistent input") {
    TempDir tmp;
    const std::string path = tmp.file("bad.exo");
    std::vector<ExodusBlock> with_empty = kBlocks;
    with_empty.push_back({"joints", "QUAD4", 4, {}});
    CHECK_THROWS_AS(ExodusWriter(path, "t", kX, kY, with_empty, kNodalNames, kElemNames),
                    std::invalid_argument);
    // Rejected before the file is created.
    CHECK_FALSE(fs::exists(path));
    CHECK_THROWS_AS(ExodusWriter(path, "t", kX, {0.0}, kBlocks, {}, {}), std::invalid_argument);
    std::vector<ExodusBlock> bad_node = {{"b", "TRI3", 3, {0, 1, 5}}};
    CHECK_THROWS_AS(ExodusWriter(path, "t", kX, kY, bad_node, {}, {}), std::invalid_argument);
    CHECK_THROWS_AS(ExodusWriter(path, "t", kX, kY, kBlocks, {std::string(33, 'A')}, {}),
                    std::invalid_argument);
    CHECK_THROWS_AS(ExodusWriter(path, "t", kX, kY, kBlocks, {"SXX", "SXX"}, {}),
                    std::invalid_argument);

    ExodusWriter w(path, "t", kX, kY, kBlocks, kNodalNames, kElemNames);
    auto short_nodal = nodal_frame(0);
    short_nodal[1].pop_back();
    CHECK_THROWS_AS(w.write_frame(0.0, short_nodal, elem_frame(0)), std::invalid_argument);
    auto short_elem = elem_frame(0);
    short_elem[2][1].clear();
    CHECK_THROWS_AS(w.write_frame(0.0, nodal_frame(0), short_elem), std::invalid_argument);
    CHECK(w.frames_written() == 0);
    w.write_frame(0.0, nodal_frame(0), elem_frame(0));
    CHECK(w.frames_written() == 1);
    w.close();
    w.close();  // idempotent
    CHECK_THROWS_AS(w.write_frame(1.0, nodal_frame(1), elem_frame(1)), std::logic_error);
  }

  TEST_CASE("unwritable exodus path is an OutputError naming the path") {
    TempDir tmp;
    const std::string missing_dir = tmp.file("no/such/dir/out.exo");
    std::string msg = output_error_message(
        [&] { ExodusWriter(missing_dir, "t", kX, kY, kBlocks, kNodalNames, kElemNames); });
    CHECK(msg.find(missing_dir) != std::string::npos);
    CHECK(msg.find("No such file or directory") != std::string::npos);
    CHECK(msg.find("creating the file") != std::string::npos);

    // A regular file where a directory should be: fails for root too.
    const std::string plain_file = tmp.file("plain");
    std::ofstream(plain_file) << "not a directory\n";
    const std::string under_file = plain_file + "/out.exo";
    msg = output_error_message(
        [&] { ExodusWriter(under_file, "t", kX, kY, kBlocks, kNodalNames, kElemNames); });
    CHECK(msg.find(under_file) != std::string::npos);

    // netCDF unlinks a path it fails to create: a device or FIFO given as the output
    // must be refused untouched.
    const std::string fifo = tmp.file("fifo");
    REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
    msg = output_error_message(
        [&] { ExodusWriter(fifo, "t", kX, kY, kBlocks, kNodalNames, kElemNames); });
    CHECK(msg.find("not a regular file") != std::string::npos);
    msg = output_error_message([&] { HistoryWriter(fifo, "t", kHistoryVars); });
    CHECK(msg.find("not a regular file") != std::string::npos);
    CHECK(fs::is_fifo(fifo));

    // A read-only directory stops everyone but root, who is not bound by modes.
    if (geteuid() != 0) {
      const fs::path ro = tmp.path / "readonly";
      fs::create_directory(ro);
      fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
      const std::string ro_file = (ro / "out.exo").string();
      msg = output_error_message(
          [&] { ExodusWriter(ro_file, "t", kX, kY, kBlocks, kNodalNames, kElemNames); });
      CHECK(msg.find(ro_file) != std::string::npos);
      fs::permissions(ro, fs::perms::owner_all);
    } else {
      MESSAGE("running as root: read-only directory case skipped");
    }
  }

  TEST_CASE("a writer killed without close leaves every synced frame readable") {
    TempDir tmp;
    const std::string path = tmp.file("killed.exo");
    run_then_sigkill([&] {
      // Deliberately leaked: the process dies with the file still open.
      auto* w = new ExodusWriter(path, "killed", kX, kY, kBlocks, kNodalNames, kElemNames);
      for (size_t f = 0; f < 3; ++f) w->write_frame(kTimes[f], nodal_frame(f), elem_frame(f));
    });
    NcReader nc(path);
    CHECK(nc.att_text(NC_GLOBAL, "title") == "killed");
    check_reference_frames(nc, 3);

    // _exit skips every destructor and atexit handler as well.
    const std::string exited = tmp.file("exited.exo");
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      try {
        auto* w = new ExodusWriter(exited, "exited", kX, kY, kBlocks, kNodalNames, kElemNames);
        for (size_t f = 0; f < 3; ++f) w->write_frame(kTimes[f], nodal_frame(f), elem_frame(f));
      } catch (...) {
        _exit(3);
      }
      _exit(0);
    }
    int wstatus = 0;
    REQUIRE(waitpid(pid, &wstatus, 0) == pid);
    REQUIRE(WIFEXITED(wstatus));
    REQUIRE(WEXITSTATUS(wstatus) == 0);
    NcReader nc2(exited);
    check_reference_frames(nc2, 3);
  }

  TEST_CASE("history file has CF time, units and one row per append") {
    TempDir tmp;
    const std::string path = reference_dir(tmp) + "/tiny_history.nc";
    write_reference_history(path, 5);

    NcReader nc(path);
    CHECK(nc.format() == NC_FORMAT_64BIT_OFFSET);
    CHECK(nc.att_text(NC_GLOBAL, "title") == "fdem-cl test history");
    CHECK(nc.att_text(NC_GLOBAL, "Conventions") == "CF-1.8");
    CHECK(nc.att_text(NC_GLOBAL, "source") == "fdem-cl");
    int unlimited = -1;
    REQUIRE(nc_inq_unlimdim(nc.id, &unlimited) == NC_NOERR);
    int time_dim = -1;
    REQUIRE(nc_inq_dimid(nc.id, "time", &time_dim) == NC_NOERR);
    CHECK(unlimited == time_dim);
    REQUIRE(nc.dim_len("time") == 5);

    const int time = nc.var("time");
    CHECK(nc.att_text(time, "units") == "s");
    CHECK(nc.att_text(time, "standard_name") == "time");
    CHECK_FALSE(nc.att_text(time, "long_name").empty());
    const auto times = nc.doubles("time", 5);
    for (size_t r = 0; r < 5; ++r) CHECK(times[r] == 1.0e-4 * static_cast<double>(r));

    for (size_t k = 0; k < kHistoryVars.size(); ++k) {
      const int id = nc.var(kHistoryVars[k].name);
      nc_type type = NC_NAT;
      REQUIRE(nc_inq_vartype(nc.id, id, &type) == NC_NOERR);
      CHECK(type == NC_DOUBLE);
      CHECK(nc.att_text(id, "units") == kHistoryVars[k].units);
      CHECK(nc.att_text(id, "long_name") == kHistoryVars[k].long_name);
      const auto values = nc.doubles(kHistoryVars[k].name, 5);
      for (size_t r = 0; r < 5; ++r) CHECK(values[r] == history_value(k, r));
    }
  }

  TEST_CASE("history writer: bad rows, bad paths and a kill") {
    TempDir tmp;
    {
      HistoryWriter h(tmp.file("h.nc"), "t", kHistoryVars);
      CHECK_THROWS_AS(h.append(0.0, {1.0}), std::invalid_argument);
      CHECK(h.rows_written() == 0);
      h.close();
      CHECK_THROWS_AS(h.append(0.0, {1.0, 2.0, 3.0}), std::logic_error);
    }

    const std::string missing_dir = tmp.file("no/such/dir/h.nc");
    std::string msg =
        output_error_message([&] { HistoryWriter(missing_dir, "t", kHistoryVars); });
    CHECK(msg.find(missing_dir) != std::string::npos);

    // A name netCDF refuses is reported with the name.
    msg = output_error_message([&] {
      HistoryWriter(tmp.file("badname.nc"), "t", {{"time", "s", "clashes with the coordinate"}});
    });
    CHECK(msg.find("'time'") != std::string::npos);

    const std::string path = tmp.file("killed_history.nc");
    run_then_sigkill([&] {
      auto* h = new HistoryWriter(path, "killed", kHistoryVars);
      for (size_t r = 0; r < 4; ++r)
        h->append(static_cast<double>(r), {history_value(0, r), history_value(1, r),
                                           history_value(2, r)});
    });
    NcReader nc(path);
    REQUIRE(nc.dim_len("time") == 4);
    const auto ke = nc.doubles("kinetic_energy", 4);
    for (size_t r = 0; r < 4; ++r) CHECK(ke[r] == history_value(0, r));
  }

  TEST_CASE("history writer with a sync interval: a killed writer keeps every row up to its last sync()") {
    TempDir tmp;
    const std::string path = tmp.file("interval_history.nc");
    run_then_sigkill([&] {
      auto* h = new HistoryWriter(path, "interval", kHistoryVars);
      h->set_sync_interval(3600.0);  // no row syncs by itself within the test
      for (size_t r = 0; r < 3; ++r)
        h->append(static_cast<double>(r), {history_value(0, r), history_value(1, r), history_value(2, r)});
      h->sync();
      for (size_t r = 3; r < 5; ++r)
        h->append(static_cast<double>(r), {history_value(0, r), history_value(1, r), history_value(2, r)});
    });
    NcReader nc(path);
    const size_t rows = nc.dim_len("time");
    CHECK(rows >= 3);
    CHECK(rows <= 5);
    const auto ke = nc.doubles("kinetic_energy", rows);
    for (size_t r = 0; r < rows; ++r) CHECK(ke[r] == history_value(0, r));
  }
}
